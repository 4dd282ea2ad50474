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
//   G is a Gaussian of standard deviation `sigma` with replicated borders (taps as
//   blurX/blurY: exact normalised weights over [-ceil(3 sigma), ceil(3 sigma)]).
//   Flat regions give s = 1 (white); beside an edge the darker side has Y' < G:
//   a dark stroke about sigma wide. eps keeps flat black regions white instead of
//   the classic 0/0 and keeps noise in the shadows from turning into scribbles.
//   Then s = s^darkness; paper grain: s * (1 - paper * n), n a fixed value noise
//   in [0, 1]; tint: s * mix(1, image', color). The result is a perceptual grey
//   level, stored so that an 8-bit output holds 255 s.
//
// Passes
//   blur_h: luma + horizontal Gaussian (shaders/pencil_blur.wgsl) -> r16f
//   blur_v: vertical Gaussian (shaders/blurY.wgsl)                -> r16f
//   sketch: dodge, grain, tint (shaders/pencil.wgsl)              -> 8-bit
//   The blurred luma is kept in a one-channel half-float texture: the dodge divides
//   by it, so 8-bit storage would band in the shadows.
EFFECT.pencil = {
    DESCRIPTION = "Pencil sketch: colour dodge of the luma with its blurred inverse (grey strokes on white).\nOptional paper grain and colour tint."
    FORMAT = rgba8-srgb
    PARAM = {
        sigma = FLOAT { DEFAULT = 5  RANGE = (0.5, 64)  DESCRIPTION = "blur standard deviation in pixels: the width of the strokes" }
        darkness = FLOAT { DEFAULT = 1  RANGE = (0.1, 10)  DESCRIPTION = "exponent on the sketch: > 1 darkens the strokes" }
        paper = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "strength of the paper grain (0: clean white paper)" }
        color = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "0: grey pencil; 1: strokes and paper tinted with the image colours" }
    }
    PASS = {
        blur_h = SHADER.pencil_blur {
            img = IN
            img.COLORSPACE = srgb
            sigma = PARAM.sigma
            OUT.FORMAT = r16f
        }
        blur_v = SHADER.blurY {
            img = PASS.blur_h
            sigma = PARAM.sigma
            OUT.FORMAT = r16f
        }
        sketch = SHADER.pencil {
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
