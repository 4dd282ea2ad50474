// fog: distance fog (linear, exponential, exponential squared) with an optional
// exponential height falloff, from the deferred renderer's linear depth.
//
// Inputs: IN (the scene), AUX.depth (linear view-space depth), and inv_proj for the
// view-space position P of a pixel (the point of its view ray at that depth;
// identity without a renderer: P = (ndc x, ndc y, depth)).
//
// Maths (shaders/effects/fog/fog.wgsl)
//   distance    L = depth (distance = depth: the view-axis distance, AUX.depth as is)
//               L = |P|   (distance = radial: Euclidean distance from the camera,
//                          which does not change when the camera turns)
//   height      with height_falloff k > 0 the fog density at world height h is
//               density(h) = density * exp(-k (h - fog_height)); along the segment
//               from the camera (height camera_height) to P (height
//               camera_height + dh, dh = dot(P, normalize(up))) its mean is
//               exp(-k (camera_height - fog_height)) * (1 - exp(-k dh)) / (k dh),
//               so the optical distance is
//               D = L * exp(-k (camera_height - fog_height)) * (1 - exp(-k dh)) / (k dh)
//               (k = 0: D = L). `up` is the world's up direction in view space:
//               (0, 1, 0) for a camera that does not pitch or roll; the renderer's
//               view matrix times world up otherwise.
//   transmittance f(D):
//               linear:       f = clamp((end - D) / (end - start), 0, 1)
//               exponential:  f = exp(-density * D)
//               exp-squared:  f = exp(-(density * D)^2)
//   out = vec4(mix(IN.rgb, color, 1 - f), IN.a)
//   f(0) = 1 in every mode (start >= 0), so depth 0 leaves a pixel unchanged; so do
//   infinite and NaN depths. (The deferred renderer writes depth = far for its
//   background: that gets the fog of the far distance, like distant geometry.) For the
//   exponential mode with a height falloff this is the exact integral of the
//   density along the ray (Quilez's analytic height fog); the other modes apply
//   their curve to the same optical distance D.
//
// Limitations: homogeneous fog colour (no in-scattering from lights); the height
// falloff needs the camera height and the world up in view space as parameters
// (only proj / inv_proj are standard values).
//
// Parameters: mode, distance, color, density, start, end, height_falloff,
// fog_height, camera_height, up (below).
// Passes: one, `fog` (two texel loads per pixel), in IN's format.
EFFECT.fog = {
    DESCRIPTION = "Distance fog from AUX.depth: linear, exponential or exponential-squared, optional height falloff.\nout = mix(IN, color, 1 - f(D)); D = depth or radial distance, scaled by the mean height density."
    PARAM = {
        mode = ENUM { VALUES = (linear, exponential, exponential_squared)  DEFAULT = exponential  DESCRIPTION = "transmittance curve f(D)" }
        distance = ENUM { VALUES = (depth, radial)  DEFAULT = depth  DESCRIPTION = "depth: view-axis distance (AUX.depth); radial: distance from the camera" }
        color = VEC3 { DEFAULT = (0.5, 0.6, 0.7)  RANGE = (0, 65504)  DESCRIPTION = "fog colour (linear)" }
        density = FLOAT { DEFAULT = 0.05  RANGE = (0, 1000000)  DESCRIPTION = "exponential modes: extinction per view-space unit" }
        start = FLOAT { DEFAULT = 0  RANGE = (0, 1000000000)  DESCRIPTION = "linear mode: distance where the fog starts" }
        end = FLOAT { DEFAULT = 100  RANGE = (0, 1000000000)  DESCRIPTION = "linear mode: distance of full fog" }
        height_falloff = FLOAT { DEFAULT = 0  RANGE = (0, 1000000)  DESCRIPTION = "density falls by a factor e per 1 / height_falloff units of height (0: uniform fog)" }
        fog_height = FLOAT { DEFAULT = 0  RANGE = (-1000000000, 1000000000)  DESCRIPTION = "world height where the density is `density`" }
        camera_height = FLOAT { DEFAULT = 0  RANGE = (-1000000000, 1000000000)  DESCRIPTION = "world height of the camera" }
        up = VEC3 { DEFAULT = (0, 1, 0)  RANGE = (-1, 1)  DESCRIPTION = "world up direction in view space" }
    }
    PASS = {
        fog = SHADER.fog {
            img = IN
            depth = AUX.depth
            color = PARAM.color
            density = PARAM.density
            start = PARAM.start
            end = PARAM.end
            height_falloff = PARAM.height_falloff
            fog_height = PARAM.fog_height
            camera_height = PARAM.camera_height
            up = PARAM.up
            DEFINE.MODE = PARAM.mode
            DEFINE.DISTANCE = PARAM.distance
            OUT.FORMAT = IN
        }
    }
    OUT = fog
}
