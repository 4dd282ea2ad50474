// chroma_key_temporal: chroma_key for sequences, with a temporally stable matte.
//
// What it does
//   Runs the built-in chroma_key (nested: EFFECT.chroma_key, its straight output)
//   and smooths its alpha over time where the input colour is stable, so noise on
//   the backdrop (grain, compression, sensor noise) does not make the soft edges
//   and the noisy parts of the backdrop flicker from frame to frame. Where the
//   colour changes (the foreground moves), the matte follows the current frame.
//
// Maths
//   keyed = chroma_key(IN) (see effects/chroma_key.fx: alpha from the CbCr distance
//   to the key colour, soft band, spill suppression), a = keyed.alpha.
//   Pass `matte` (shaders/effects/chroma_key_temporal/chroma_key_temporal_matte.wgsl), per pixel, on the sRGB-encoded input
//   colours of this frame and the previous one (IN, IN[-1]):
//       D = IN - IN[-1]                                  (r, g, b)
//       m = max(|mean of D over 3x3|, |D| / 3), averaged over r, g, b
//       h = strength * exp(-m^2 / (2 sigma^2))           history weight
//       matte = (1 - h) * a + h * matte[-1]              (feedback PASS.matte[-1])
//   i.e. exponential smoothing of the matte with a weight that falls to 0 where the
//   colour changes by a few sigma. For i.i.d. flicker of the alpha and a constant
//   h, the alpha's variance falls by (1 - h) / (1 + h) (0.11 at h = 0.8) and its
//   frame-to-frame differences by more. The 3x3 mean keeps the noise itself from
//   counting as motion; the |D| / 3 term catches changes of single pixels.
//   Frame 0 (no history): matte = a.
//   Pass `out` (shaders/effects/chroma_key_temporal/chroma_key_temporal_out.wgsl): keyed colour (despilled, straight) with the
//   smoothed matte, as straight RGBA, premultiplied RGBA, or the matte as grey.
//
// Parameters: key, tolerance, softness, spill (forwarded to chroma_key), strength,
// sigma, output (below).
//
// Passes: `keyed` (EFFECT.chroma_key: keyed/key, rgba8-srgb), `matte` (r16f, the
// smoothed alpha; also its own history), `out` (rgba16f).
// Temporal behaviour: reads IN[-1] (one earlier frame) and its own previous matte;
// no latency. A colour change that keeps the same sRGB values frame to frame (a
// static foreground) keeps being smoothed, as intended.
EFFECT.chroma_key_temporal = {
    DESCRIPTION = "Chroma key for sequences: chroma_key with its matte smoothed over time where the colour is stable.\nmatte = (1 - h) alpha + h matte[-1], h = strength * exp(-m^2 / 2 sigma^2), m = local colour change."
    PARAM = {
        key = VEC3 { DEFAULT = (0.2275, 0.8235, 0.2549)  RANGE = (0, 1)  DESCRIPTION = "backdrop colour, sRGB-encoded 0..1 (default: RGB 58,210,65)" }
        tolerance = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "chroma distance below which pixels are fully transparent" }
        softness = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "width of the band from transparent to opaque (0: hard matte)" }
        spill = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "fraction of key-coloured chroma removed from the foreground" }
        strength = FLOAT { DEFAULT = 0.8  RANGE = (0, 0.99)  DESCRIPTION = "weight of the previous matte where the colour is stable (0: plain chroma_key)" }
        sigma = FLOAT { DEFAULT = 0.05  RANGE = (0.0001, 10)  DESCRIPTION = "colour change (sRGB-encoded 0..1) that counts as motion: about the noise level or above" }
        output = ENUM { VALUES = (straight, premultiplied, matte)  DEFAULT = straight  DESCRIPTION = "straight RGBA, premultiplied RGBA, or the matte as grey" }
    }
    PASS = {
        keyed = EFFECT.chroma_key {
            IN = IN
            key = PARAM.key
            tolerance = PARAM.tolerance
            softness = PARAM.softness
            spill = PARAM.spill
        }
        matte = SHADER.chroma_key_temporal_matte {
            keyed = PASS.keyed
            cur = IN
            cur.COLORSPACE = srgb
            prev = IN[-1]
            prev.COLORSPACE = srgb
            hist = PASS.matte[-1]
            strength = PARAM.strength
            sigma = PARAM.sigma
            OUT.FORMAT = r16f
        }
        out = SHADER.chroma_key_temporal_out {
            keyed = PASS.keyed
            matte = PASS.matte
            DEFINE.OUTPUT = PARAM.output
        }
    }
    OUT = out
}
