// edges: Sobel edge detection.
//
// What it does
//   Computes the Sobel gradient magnitude of the image's luma and writes it as a
//   grey edge map (`mode = magnitude`), or draws it over the image in a colour
//   (`mode = overlay`).
//
// Maths (shaders/effects/edges/edges_sobel.wgsl)
//   The luma is taken on sRGB-encoded values (perceptual, like CPU tools working on
//   8-bit files; for an 8-bit input this costs nothing: the texture is read through
//   its raw view), with Rec.709 weights:
//       Y' = 0.2126 R' + 0.7152 G' + 0.0722 B'
//   Sobel kernels on the 3x3 neighbourhood, border replicated (clamped coordinates):
//       Gx = [-1 0 1; -2 0 2; -1 0 1],  Gy = [-1 -2 -1; 0 0 0; 1 2 1]
//       e  = scale * sqrt(Gx^2 + Gy^2) / 4
//   The division by 4 normalises a vertical or horizontal unit step to e = scale on
//   the two pixels beside it (a 45-degree step gives up to 1.06). Values with
//   e < threshold become 0.
//   magnitude: grey level v = e (1 - e with invert), clamped to [0, 1];
//   overlay:   v = mix(image', color, min(e, 1)) in sRGB-encoded values.
//   v is a perceptual grey level: the pass decodes it to linear light, so an 8-bit
//   output file holds round(255 v). Alpha is kept.
//
// Parameters: mode, scale, threshold, invert, color (below).
// Passes: one, `sobel` (9 texel loads per pixel), 8-bit output.
EFFECT.edges = {
    DESCRIPTION = "Sobel edge detection on luma (edge map or overlay), replicated border.\nGradient magnitude of Rec.709 luma on sRGB-encoded values, normalised so a unit step gives 1."
    FORMAT = rgba8-srgb
    PARAM = {
        mode = ENUM { VALUES = (magnitude, overlay)  DEFAULT = magnitude  DESCRIPTION = "magnitude: grey edge map; overlay: edges drawn over the image in `color`" }
        scale = FLOAT { DEFAULT = 1  RANGE = (0, 100)  DESCRIPTION = "gain on the gradient magnitude (1: a full black-to-white step gives 1)" }
        threshold = FLOAT { DEFAULT = 0  RANGE = (0, 10)  DESCRIPTION = "magnitudes (after scale) below this become 0" }
        invert = BOOL { DEFAULT = false  DESCRIPTION = "magnitude mode: dark edges on white" }
        color = VEC3 { DEFAULT = (0, 0, 0)  RANGE = (0, 1)  DESCRIPTION = "overlay mode: colour of the edges (sRGB-encoded 0..1)" }
    }
    PASS = {
        sobel = SHADER.edges_sobel {
            img = IN
            img.COLORSPACE = srgb
            scale = PARAM.scale
            threshold = PARAM.threshold
            invert = PARAM.invert
            color = PARAM.color
            DEFINE.MODE = PARAM.mode
        }
    }
    OUT = sobel
}
