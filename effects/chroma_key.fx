// chroma_key: green/blue-screen keying.
//
// What it does
//   Makes the pixels close to a backdrop colour transparent (alpha 0), the others
//   opaque, with a soft band in between, and removes the backdrop's colour cast
//   (spill) from the foreground. The only input is IN; `chroma_composite` puts the
//   result over a background image.
//
// Maths (shaders/effects/chroma_key/chroma_key.wgsl)
//   On sRGB-encoded values (free for 8-bit inputs: raw view), Rec.709 Y'CbCr:
//       Y' = 0.2126 R' + 0.7152 G' + 0.0722 B'
//       Cb = (B' - Y') / 1.8556,  Cr = (R' - Y') / 1.5748
//   Distance in the chroma plane only, so the backdrop's brightness does not matter:
//       d = |(Cb, Cr) - (Cb, Cr)_key|
//       alpha = clamp((d - tolerance) / softness, 0, 1) * alpha_in
//   (monotonic in d; a hard step at `tolerance` when softness = 0). For the default
//   key, d ranges over about [0, 0.75]; grey and skin tones are about 0.35-0.45 away.
//   Spill suppression: with k the unit vector of the key's chroma,
//       (Cb, Cr) -= spill * max((Cb, Cr) . k, 0) * k
//   i.e. the part of a pixel's chroma that points towards the key colour is
//   reduced, luma kept (greenish fringes and reflections turn neutral; colours on
//   the other side of the chroma plane are untouched). Yellows and cyans next to
//   a green key shift slightly, as with every despill.
//
// Output: STRAIGHT (not premultiplied) RGBA by default, colour despilled, in an
// 8-bit sRGB texture; `output = premultiplied` multiplies rgb by alpha (in linear
// light); `output = matte` writes the matte as grey (an 8-bit file holds 255 alpha).
//
// Parameters: key, tolerance, softness, spill, output (below).
// Passes: one, `key`.
EFFECT.chroma_key = {
    DESCRIPTION = "Chroma key: alpha from the CbCr distance to a key colour, soft band, spill suppression.\nStraight (non-premultiplied) RGBA; output = premultiplied or matte for the other forms."
    FORMAT = rgba8-srgb
    PARAM = {
        key = VEC3 { DEFAULT = (0.2275, 0.8235, 0.2549)  RANGE = (0, 1)  DESCRIPTION = "backdrop colour, sRGB-encoded 0..1 (default: RGB 58,210,65)" }
        tolerance = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "chroma distance below which pixels are fully transparent" }
        softness = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "width of the band from transparent to opaque (0: hard matte)" }
        spill = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "fraction of key-coloured chroma removed from the foreground" }
        output = ENUM { VALUES = (straight, premultiplied, matte)  DEFAULT = straight  DESCRIPTION = "straight RGBA, premultiplied RGBA, or the matte as grey" }
    }
    PASS = {
        key = SHADER.chroma_key {
            img = IN
            img.COLORSPACE = srgb
            key = PARAM.key
            tolerance = PARAM.tolerance
            softness = PARAM.softness
            spill = PARAM.spill
            DEFINE.OUTPUT = PARAM.output
        }
    }
    OUT = key
}
