// pencil: pencil sketch by colour dodge.
//
// What it does
//   The classic "pencil sketch" of image editors: a grey drawing where edges become
//   dark strokes on white paper, flat areas white. Optional paper grain and colour
//   tint.
//
// Maths
//   Y' = Rec.709 luma of the sRGB-encoded image (perceptual; for an 8-bit input
//   this costs nothing, the texture is read through its raw view).
//   Colour dodge of Y' with the blurred inverse: Y' / (1 - blur(1 - Y')), and since
//   the blur is linear, 1 - blur(1 - Y') = blur(Y') = G, so
//       s = clamp((Y' + eps) / (G + eps), 0, 1),   eps = 0.01
//   G is a Gaussian of standard deviation `sigma` (input pixels), replicated
//   border. Flat regions give s = 1 (white); beside an edge the darker side has
//   Y' < G: a dark stroke about sigma wide. eps keeps flat black regions white
//   instead of the classic 0/0 and keeps noise in the shadows from turning into
//   scribbles. Then s = s^darkness; paper grain: s * (1 - paper * n), n a fixed
//   value noise in [0, 1]; tint: s * mix(1, image', color). The result is a
//   perceptual grey level, stored so that an 8-bit output holds 255 s.
//
// Passes
//   blur_h: luma + horizontal Gaussian, half size   (shaders/effects/pencil/pencil_blur.wgsl) -> r16f
//   blur_v: vertical Gaussian, half size            (pencil_blur, VERTICAL)     -> r16f
//           (both blurs are compute passes under compute execution: each input
//           line under a workgroup's outputs is staged once in workgroup memory)
//   sketch: dodge, grain, tint at full size         (shaders/effects/pencil/pencil_sketch.wgsl)       -> 8-bit
//   G is smooth, so it is computed at half resolution (sigma / 2 half-size pixels,
//   blur_h's bilinear taps averaging 2x2 input pixels) and upsampled bilinearly:
//   a quarter of the pixels and half the taps, about 3x faster at 1920x1080 than
//   at full size, within 45 dB PSNR of the full-size result for sigma = 5 (the
//   effective sigma is about sqrt(sigma^2 + 0.9)). It is kept in a one-channel
//   half-float texture: the dodge divides by it, so 8-bit storage would band in
//   the shadows.
EFFECT.pencil = {
    DESCRIPTION = "Pencil sketch: colour dodge of the luma with its blurred inverse (grey strokes on white).\nOptional paper grain and colour tint."
    FORMAT = rgba8-srgb
    PARAM = {
        sigma = FLOAT { DEFAULT = 5  RANGE = (1, 64)  DESCRIPTION = "blur standard deviation in pixels: the width of the strokes" }
        darkness = FLOAT { DEFAULT = 1  RANGE = (0.1, 10)  DESCRIPTION = "exponent on the sketch: > 1 darkens the strokes" }
        paper = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "strength of the paper grain (0: clean white paper)" }
        color = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "0: grey pencil; 1: strokes and paper tinted with the image colours" }
    }
    PASS = {
        blur_h = SHADER.pencil_blur {
            img = IN
            img.COLORSPACE = srgb
            sigma = PARAM.sigma
            scale = 0.5
            OUT.SCALE = (0.5, 0.5)
            OUT.FORMAT = r16f
        }
        blur_v = SHADER.pencil_blur {
            img = PASS.blur_h
            sigma = PARAM.sigma
            scale = 0.5
            DEFINE.VERTICAL = 1
            OUT.SCALE = (0.5, 0.5)
            OUT.FORMAT = r16f
        }
        sketch = SHADER.pencil_sketch {
            img = IN
            img.COLORSPACE = srgb
            blurred = PASS.blur_v
            darkness = PARAM.darkness
            paper = PARAM.paper
            color = PARAM.color
        }
    }
    OUT = sketch
}
