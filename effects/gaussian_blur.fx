// gaussian_blur: separable Gaussian blur.
EFFECT.gaussian_blur = {
    DESCRIPTION = "Gaussian blur (separable, exact normalised weights, replicated border).\nMatches OpenCV's GaussianBlur(img, (0,0), sigma, borderType=BORDER_REPLICATE)."
    FORMAT = IN
    PARAM = {
        sigma = FLOAT { DEFAULT = 2  RANGE = (0.1, 128)  DESCRIPTION = "standard deviation in pixels" }
    }
    PASS = {
        horizontal = SHADER.gauss {
            img = IN
            sigma = PARAM.sigma
        }
        vertical = SHADER.gauss {
            img = PASS.horizontal
            sigma = PARAM.sigma
            DEFINE.VERTICAL = 1
        }
    }
    OUT = vertical
}
