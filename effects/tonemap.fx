// tonemap: HDR to display range.
//
// In linear light, x = max(in, 0) * 2^exposure, then the operator:
//   reinhard:  per channel y = x / (1 + x);  with white > 0 (Reinhard extended):
//              y = x (1 + x / white^2) / (1 + x), so that x = white maps to 1
//   aces:      per channel, Krzysztof Narkowicz's fit of the ACES filmic curve (2015):
//              y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//              (no built-in 0.6 pre-exposure: set exposure = -0.737 for it)
//   neutral:   Khronos PBR Neutral, per its published specification (the glTF
//              Sample Viewer's default): offset = (m < 0.08 ? m - 6.25 m^2 : 0.04)
//              with m the smallest channel, c = x - offset; colours whose largest
//              channel p stays below 0.8 - 0.04 are unchanged (base colours
//              reproduce); above, p' = 1 - d^2 / (p + d - 0.76) with d = 0.24,
//              c *= p' / p, then mixed towards (p', p', p') by
//              g = 1 - 1 / (0.15 (p - p') + 1) (desaturation 0.15)
//   agx:       AgX (Troy Sobotka; Blender's default view transform): the inset
//              matrix, log2 over [-12.47393, 4.026069] EV mapped to [0, 1], the
//              base contrast sigmoid as the 6th-order polynomial fit of Benjamin
//              Wrensch's "minimal AgX" (no LUT), the look (base, or punchy: power
//              1.35 and saturation 1.4), the outset matrix, then a 2.2 power back
//              to linear display light
//   out = clamp(y, 0, 1)
// The result is display-referred linear light in [0, 1], ready for an 8-bit file
// (the runtime applies the sRGB encoding when writing it).
//
// Parameters:
//   exposure  stops applied before the curve (-20 .. 20, default 0)
//   operator  reinhard | aces | neutral | agx (default aces)
//   white     Reinhard extended white point, in scene values after exposure
//             (0 = plain Reinhard, the default; ignored by the others)
//   look      AgX look: base | punchy (default base; ignored by the others)
//
// Passes: tonemap (SHADER.tonemap, input size).
EFFECT.tonemap = {
    DESCRIPTION = "Tone mapping of HDR images to [0, 1]: exposure, then Reinhard (extended), ACES (Narkowicz fit), Khronos PBR Neutral or AgX (base or punchy)."
    PARAM = {
        exposure = FLOAT { DEFAULT = 0  RANGE = (-20, 20)  DESCRIPTION = "exposure in stops applied before the curve" }
        operator = ENUM { VALUES = (reinhard, aces, neutral, agx)  DEFAULT = aces  DESCRIPTION = "tone curve: reinhard (x / (1 + x), extended with white), aces (Narkowicz fit), neutral (Khronos PBR Neutral) or agx (AgX, Blender's)" }
        white = FLOAT { DEFAULT = 0  RANGE = (0, 65000)  DESCRIPTION = "Reinhard extended: the value mapped to 1; 0 = plain Reinhard" }
        look = ENUM { VALUES = (base, punchy)  DEFAULT = base  DESCRIPTION = "AgX look: base contrast, or punchy (power 1.35, saturation 1.4)" }
    }
    PASS = {
        tonemap = SHADER.tonemap {
            img = IN
            exposure = PARAM.exposure
            white = PARAM.white
            DEFINE.OPERATOR = PARAM.operator
            DEFINE.LOOK = PARAM.look
        }
    }
    OUT = tonemap
}
