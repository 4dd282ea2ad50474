// color_grade: ASC CDL and lift/gamma/gain colour correction.
//
// Order of operations, per pixel, on the values as they come (linear light for
// the runtime's usual inputs), alpha kept:
//   1. ASC CDL slope/offset/power:
//        v = in * slope + offset;  clamp: v = clamp(v, 0, 1);  v = v^power
//      (without clamp, values <= 0 skip the power and pass unchanged)
//   2. ASC CDL saturation with Rec. 709 luma weights (ASC CDL v1.2):
//        luma = 0.2126 r + 0.7152 g + 0.0722 b;  v = luma + saturation * (v - luma)
//        clamp: v = clamp(v, 0, 1)
//   3. lift/gamma/gain:
//        v = gain * (v + lift * (1 - v));  v = v^(1 / gamma)   (v > 0)
//      lift moves black (0 -> gain * lift) and keeps 1 fixed before the gain;
//      gamma > 1 brightens the midtones.
// With the default values every step is the identity.
//
// Parameters (VEC3 values are per R, G, B):
//   slope (1,1,1)  offset (0,0,0)  power (1,1,1)  saturation 1
//   lift (0,0,0)   gamma (1,1,1)   gain (1,1,1)
//   clamp  true: clamp to [0, 1] after SOP and saturation, as the ASC spec does;
//          false: no clamping, for HDR values above 1
//
// Passes: grade (SHADER.color_grade, input size and format).
EFFECT.color_grade = {
    DESCRIPTION = "Colour grading: ASC CDL slope/offset/power and saturation, then lift/gamma/gain.\nThe defaults are the identity: set the parameters to grade."
    FORMAT = IN
    PARAM = {
        slope = VEC3 { DEFAULT = (1, 1, 1)  RANGE = (0, 100)  DESCRIPTION = "ASC CDL slope (multiplier)" }
        offset = VEC3 { DEFAULT = (0, 0, 0)  RANGE = (-10, 10)  DESCRIPTION = "ASC CDL offset (added after the slope)" }
        power = VEC3 { DEFAULT = (1, 1, 1)  RANGE = (0.01, 100)  DESCRIPTION = "ASC CDL power (exponent)" }
        saturation = FLOAT { DEFAULT = 1  RANGE = (0, 10)  DESCRIPTION = "ASC CDL saturation (Rec. 709 luma): 0 grey, 1 unchanged" }
        lift = VEC3 { DEFAULT = (0, 0, 0)  RANGE = (-1, 1)  DESCRIPTION = "raises (or lowers) the blacks, keeps white" }
        gamma = VEC3 { DEFAULT = (1, 1, 1)  RANGE = (0.01, 100)  DESCRIPTION = "midtones: v^(1 / gamma); above 1 brightens" }
        gain = VEC3 { DEFAULT = (1, 1, 1)  RANGE = (0, 100)  DESCRIPTION = "multiplier of the whole range" }
        clamp = BOOL { DEFAULT = true  DESCRIPTION = "clamp to [0, 1] after SOP and saturation (ASC); false keeps HDR values" }
    }
    PASS = {
        grade = SHADER.color_grade {
            img = IN
            slope = PARAM.slope
            offset = PARAM.offset
            power = PARAM.power
            saturation = PARAM.saturation
            lift = PARAM.lift
            gamma = PARAM.gamma
            gain = PARAM.gain
            clamp_range = PARAM.clamp
        }
    }
    OUT = grade
}
