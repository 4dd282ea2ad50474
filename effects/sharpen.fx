// sharpen: unsharp mask.
//
//   d   = in - gauss(in, sigma)                      per channel
//   out = max(in + amount * d, 0)   where |d| >= threshold, else in
//
// gauss is gaussian_blur's kernel (same radius rule, replicated border); alpha is
// kept. Colour inputs are sharpened in linear light (the runtime decodes sRGB).
// Negative results (undershoot next to strong edges) are clamped to 0; 8-bit
// outputs also clip overshoot at 1.
//
// Parameters:
//   amount     strength (0 .. 20, default 1; 0 = identity)
//   sigma      standard deviation of the blur in pixels (0.1 .. 64, default 1.5)
//   threshold  per-channel differences |d| below this are not sharpened, so
//              noise and smooth areas stay as they are (0 .. 1, default 0)
//
// Passes (both at the input's size):
//   blur     SHADER.gaussian_blur                     IN -> horizontal blur, rgba16f (see
//                                             gaussian_blur.fx for why)
//   sharpen  SHADER.gaussian_blur VERTICAL UNSHARP    vertical blur of `blur`, combined
//                                             with IN in the same pass -> output,
//                                             in the input's format (under compute
//                                             execution an rgba16f output is a compute
//                                             pass from staged column segments)
EFFECT.sharpen = {
    DESCRIPTION = "Unsharp mask: in + amount * (in - gaussian_blur(in, sigma)), with a threshold."
    FORMAT = IN
    PARAM = {
        amount = FLOAT { DEFAULT = 1  RANGE = (0, 20)  DESCRIPTION = "strength; 0 leaves the image unchanged" }
        sigma = FLOAT { DEFAULT = 1.5  RANGE = (0.1, 64)  DESCRIPTION = "standard deviation of the blur in pixels" }
        threshold = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "per-channel differences below this are not sharpened" }
    }
    PASS = {
        blur = SHADER.gaussian_blur_rows {
            img = IN
            sigma = PARAM.sigma
            OUT.FORMAT = rgba16f
        }
        sharpen = SHADER.gaussian_blur {
            img = PASS.blur
            orig = IN
            sigma = PARAM.sigma
            amount = PARAM.amount
            threshold = PARAM.threshold
            DEFINE.VERTICAL = 1
            DEFINE.UNSHARP = 1
        }
    }
    OUT = sharpen
}
