// tonemap: HDR to display range.
//
// Per RGB channel (alpha kept), in linear light:
//   x = max(in, 0) * 2^exposure
//   reinhard:  y = x / (1 + x);  with white > 0 (Reinhard extended):
//              y = x (1 + x / white^2) / (1 + x), so that x = white maps to 1
//   aces:      Krzysztof Narkowicz's fit of the ACES filmic curve (2015):
//              y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//              (no built-in 0.6 pre-exposure: set exposure = -0.737 for it)
//   out = clamp(y, 0, 1)
// The result is display-referred linear light in [0, 1], ready for an 8-bit file
// (the runtime applies the sRGB encoding when writing it).
//
// Parameters:
//   exposure  stops applied before the curve (-20 .. 20, default 0)
//   operator  reinhard | aces (default aces)
//   white     Reinhard extended white point, in scene values after exposure
//             (0 = plain Reinhard, the default; ignored by aces)
//
// Passes: tonemap (SHADER.tonemap, input size).
EFFECT.tonemap = {
    DESCRIPTION = "Tone mapping of HDR images to [0, 1]: exposure, then Reinhard (extended) or ACES (Narkowicz fit)."
    PARAM = {
        exposure = FLOAT { DEFAULT = 0  RANGE = (-20, 20)  DESCRIPTION = "exposure in stops applied before the curve" }
        operator = ENUM { VALUES = (reinhard, aces)  DEFAULT = aces  DESCRIPTION = "tone curve: reinhard (x / (1 + x), extended with white) or aces (Narkowicz fit)" }
        white = FLOAT { DEFAULT = 0  RANGE = (0, 65000)  DESCRIPTION = "Reinhard extended: the value mapped to 1; 0 = plain Reinhard" }
    }
    PASS = {
        tonemap = SHADER.tonemap {
            img = IN
            exposure = PARAM.exposure
            white = PARAM.white
            DEFINE.OPERATOR = PARAM.operator
        }
    }
    OUT = tonemap
}
