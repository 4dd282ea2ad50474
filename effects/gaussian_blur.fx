// gaussian_blur: separable Gaussian blur.
//
// Weights exp(-i^2 / (2 sigma^2)) over [-r, r], normalised to a sum of 1, with
// r = (ksize - 1) / 2 and ksize = round(6 sigma + 1) | 1: OpenCV's kernel size for
// 8-bit images, so that on values used as stored (`--assume-linear`) the result
// matches cv2.GaussianBlur(img, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE)
// within 1 LSB. The border is replicated (clamp-to-edge). Colour inputs are
// blurred in linear light (the runtime decodes sRGB); all four channels are blurred.
//
// Parameters:
//   sigma  standard deviation in pixels (0.1 .. 128, default 2)
//   exact  the vertical pass: false (default): bilinear-pair taps, r + 1 fetches
//          per pixel; true: one textureLoad per texel, 2r + 1 fetches (does not
//          depend on the sampler's sub-texel precision; a little slower on
//          lavapipe). The horizontal pass always uses exact weights.
//
// Passes (both at the input's size):
//   horizontal  SHADER.gaussian_blur_rows       IN -> horizontal blur, rgba16f: a
//                                       compute pass; each 256-pixel run of a row
//                                       is read once into workgroup memory
//   vertical    SHADER.gaussian_blur VERTICAL   horizontal -> output, in the input's format
//                                       (8-bit stays 8-bit); under compute execution
//                                       an rgba16f output is a compute pass: 32
//                                       pixels of each of 8 columns from one staged
//                                       column segment
// The intermediate is rgba16f rather than the input's format: on lavapipe
// sampling an rgba8-srgb texture with bilinear filtering costs more than sampling
// rgba16f (the sRGB decode), so for 8-bit photos this is ~10% faster overall
// (1920x1080, sigma 8: 328 vs 362 ms), and it saves an 8-bit rounding between the
// passes. (With --assume-linear, plain rgba8 would be ~20% faster.)
EFFECT.gaussian_blur = {
    DESCRIPTION = "Gaussian blur (separable, exact normalised weights, replicated border).\nKernel radius as OpenCV's GaussianBlur for 8-bit images: r = (round(6 sigma + 1) | 1 - 1) / 2."
    FORMAT = IN
    PARAM = {
        sigma = FLOAT { DEFAULT = 2  RANGE = (0.1, 128)  DESCRIPTION = "standard deviation in pixels" }
        exact = BOOL { DEFAULT = false  DESCRIPTION = "one textureLoad per texel instead of bilinear-pair taps (slower)" }
    }
    PASS = {
        horizontal = SHADER.gaussian_blur_rows {
            img = IN
            sigma = PARAM.sigma
            OUT.FORMAT = rgba16f
        }
        vertical = SHADER.gaussian_blur {
            img = PASS.horizontal
            sigma = PARAM.sigma
            DEFINE.VERTICAL = 1
            DEFINE.EXACT = PARAM.exact
        }
    }
    OUT = vertical
}
