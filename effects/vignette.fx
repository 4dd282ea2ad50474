// vignette: darkens the image towards its edges.
//
// Per pixel, with uv in 0..1 (pixel centres) and an aspect-aware distance:
//   q = (uv - center) * 2 * mix((1, 1), a, roundness)
//       a = (w / h, 1) for a landscape frame, (1, h / w) for a portrait one
//   t = clamp((length(q) - radius) / softness, 0, 1),  v = t^2 (3 - 2 t)
//   out = in * (1 - strength * v)          (rgb in linear light; alpha kept)
// roundness 1 makes the vignette a circle in pixels (distance 1 at the nearer
// edges); roundness 0 an ellipse following the frame (distance 1 at every edge
// midpoint for the default centre).
//
// Parameters:
//   strength   darkening where the transition is complete (0 .. 1, default 0.5)
//   radius     distance where the darkening starts (default 0.8)
//   softness   width of the transition (default 0.8)
//   center     centre as fractions of the width and height (default (0.5, 0.5))
//   roundness  1 circle (default) .. 0 ellipse fitted to the frame
//
// Passes: vignette (SHADER.vignette, input size and format).
EFFECT.vignette = {
    DESCRIPTION = "Vignette: smooth darkening away from a centre, circular or following the frame's aspect."
    FORMAT = IN
    PARAM = {
        strength = FLOAT { DEFAULT = 0.5  RANGE = (0, 1)  DESCRIPTION = "darkening where the transition is complete (1: black)" }
        radius = FLOAT { DEFAULT = 0.8  RANGE = (0, 4)  DESCRIPTION = "distance from the centre where darkening starts (1: nearer edge)" }
        softness = FLOAT { DEFAULT = 0.8  RANGE = (0, 4)  DESCRIPTION = "width of the transition" }
        center = VEC2 { DEFAULT = (0.5, 0.5)  RANGE = (-1, 2)  DESCRIPTION = "centre as fractions of the width and height" }
        roundness = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "1: circle in pixels; 0: ellipse following the frame" }
    }
    PASS = {
        vignette = SHADER.vignette {
            img = IN
            strength = PARAM.strength
            radius = PARAM.radius
            softness = PARAM.softness
            center = PARAM.center
            roundness = PARAM.roundness
        }
    }
    OUT = vignette
}
