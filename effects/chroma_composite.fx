// chroma_composite: chroma key + composite over a background image.
//
// What it does
//   Keys out the backdrop of IN exactly like `chroma_key` (same parameters, same
//   maths: see effects/chroma_key.fx and shaders/effects/chroma_key/chroma_key.wgsl) and puts the
//   despilled foreground over AUX.background (`fxrun ... --aux background=FILE`,
//   same size as the input), in linear light:
//       rgb = fg * a + bg * (1 - a),   alpha = a + bg.alpha * (1 - a)
//
// Passes: one, `composite` (the chroma_key shader with COMPOSITE = 1), so keying
// and compositing cost one texture write.
EFFECT.chroma_composite = {
    DESCRIPTION = "Chroma key IN and composite it over AUX.background (--aux background=FILE).\nSame keyer as chroma_key, in one pass."
    FORMAT = rgba8-srgb
    PARAM = {
        key = VEC3 { DEFAULT = (0.2275, 0.8235, 0.2549)  RANGE = (0, 1)  DESCRIPTION = "backdrop colour, sRGB-encoded 0..1 (default: RGB 58,210,65)" }
        tolerance = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "chroma distance below which pixels are fully transparent" }
        softness = FLOAT { DEFAULT = 0.1  RANGE = (0, 2)  DESCRIPTION = "width of the band from transparent to opaque (0: hard matte)" }
        spill = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "fraction of key-coloured chroma removed from the foreground" }
    }
    PASS = {
        composite = SHADER.chroma_key {
            img = IN
            img.COLORSPACE = srgb
            bg = AUX.background
            key = PARAM.key
            tolerance = PARAM.tolerance
            softness = PARAM.softness
            spill = PARAM.spill
            DEFINE.COMPOSITE = 1
        }
    }
    OUT = composite
}
