// ssao: screen-space ambient occlusion from the deferred renderer's G-buffer.
//
// What it does
//   Darkens creases, corners and contact areas of a rendered scene: for every pixel
//   it tests how much of the hemisphere above the surface is blocked by nearby
//   geometry, blurs that estimate without crossing depth or normal discontinuities,
//   and multiplies the scene (IN) by it.
//
// Inputs: IN (the lit scene), AUX.depth (linear view-space depth), AUX.normal
// (view-space normal), and the camera's proj / inv_proj standard values (identity
// without a renderer: then view x, y = ndc x, y, an orthographic camera).
//
// Maths (shaders/effects/ssao/ssao_occlusion.wgsl)
//   P = view-space position of the pixel: the point of its view ray (unprojected
//   with inv_proj) whose coordinate along the view axis equals AUX.depth; n = its
//   normal, turned towards the camera. A tangent frame (t, b, n) is rotated about n
//   by a per-pixel angle from a 4x4 tiled hash (the rotation-noise texture, computed
//   in the shader). `samples` kernel points k_i lie in the unit hemisphere around
//   n: directions uniform over the hemisphere (height 1 - (i + 1/2) / samples) on a
//   golden-angle spiral, lengths mix(0.1, 1, t^2) (t: base-2 radical inverse of i),
//   so that samples crowd near P.
//       S_i = P + radius * (k_i.x t + k_i.y b + k_i.z n)
//   S_i is projected with proj to a pixel x_i (outside the image or behind the camera:
//   the sample is open); Q_i = the scene point at x_i, reconstructed from its depth.
//       occluded_i = depth(Q_i) < depth(S_i) - bias   and   dot(Q_i - P, n) > bias
//   (a point on or below the tangent plane cannot block the hemisphere: this keeps
//   flat and grazing surfaces free of self-occlusion from pixel quantisation), with
//   the range check r_i = 1 - smoothstep(radius, 2 radius, |Q_i - P|) fading out
//   occluders farther than the radius (a foreground silhouette does not darken the
//   background behind it).
//       ao = clamp(1 - intensity * sum_i(occluded_i r_i) / samples, 0, 1)
//   Pixels without geometry (depth 0, infinite or NaN; zero normal) get ao = 1.
//
// Blur and composite (shaders/effects/ssao/ssao_blur.wgsl)
//   5x5 bilateral blur, spatial weights [0.5 1 1 1 0.5] per axis (each phase of the
//   4x4 noise gets the same weight, so its pattern cancels on flat surfaces), times
//       exp(-(dot(Q - P, n_p) / (depth_tolerance * depth_p))^2) * max(dot(n_p, n_q), 0)^8
//   so taps off the tangent plane of the pixel (across a depth step) or facing another
//   way do not count. out = IN.rgb * ao (alpha kept), or (ao, ao, ao, 1) with
//   output = ao.
//
// Parameters:
//   radius           hemisphere radius in view-space units (default 0.5)
//   intensity        occlusion strength (default 2; 0 = unchanged)
//   samples          kernel size, 4..64 (default 16; a shader define: a constant loop)
//   bias             view-space bias of both occlusion tests (default 0.02)
//   depth_tolerance  blur: plane distance, relative to depth, where a tap's weight
//                    falls to 1/e (default 0.02)
//   blur             false: skip the blur (raw, noisy AO)
//   output           composite (IN * ao) or ao (the occlusion alone, grey)
//
// Limitations: screen-space: what is hidden or off-screen cannot occlude (a sample
// behind a foreground silhouette counts as open, so AO fades beside silhouettes);
// sample points, not rays, so a 90-degree corner gets about 0.75-0.8 at
// intensity 1, hence the default 2 (about 0.5-0.6: visible contact shadows on an
// ordinary scene; at 1 the built-in room's AO is barely visible).
//
// Passes:
//   ao     SHADER.ssao_occlusion       AUX.depth, AUX.normal -> raw AO (r16f, input size)
//   final  SHADER.ssao_blur  ao, AUX.depth, AUX.normal, IN -> blurred AO applied
//                            (in IN's format)
EFFECT.ssao = {
    DESCRIPTION = "Screen-space ambient occlusion (normal-oriented hemisphere, bilateral blur) from AUX.depth and AUX.normal.\nNeeds the deferred renderer's G-buffer (or --aux depth=... --aux normal=...)."
    PARAM = {
        radius = FLOAT { DEFAULT = 0.5  RANGE = (0.0001, 100000)  DESCRIPTION = "hemisphere radius in view-space units" }
        intensity = FLOAT { DEFAULT = 2  RANGE = (0, 100)  DESCRIPTION = "occlusion strength: ao = 1 - intensity * occluded fraction" }
        samples = INT { DEFAULT = 16  RANGE = (4, 64)  DESCRIPTION = "hemisphere samples per pixel" }
        bias = FLOAT { DEFAULT = 0.02  RANGE = (0, 100000)  DESCRIPTION = "view-space bias of the depth and tangent-plane tests" }
        depth_tolerance = FLOAT { DEFAULT = 0.02  RANGE = (0.00001, 10)  DESCRIPTION = "blur: distance from the pixel's tangent plane, relative to its depth, where a tap's weight falls to 1/e" }
        blur = BOOL { DEFAULT = true  DESCRIPTION = "bilateral blur of the raw (noisy) occlusion" }
        output = ENUM { VALUES = (composite, ao)  DEFAULT = composite  DESCRIPTION = "composite: scene times AO; ao: the occlusion alone (grey)" }
    }
    PASS = {
        ao = SHADER.ssao_occlusion {
            depth = AUX.depth
            normal = AUX.normal
            radius = PARAM.radius
            intensity = PARAM.intensity
            bias = PARAM.bias
            DEFINE.SAMPLES = PARAM.samples
            OUT.FORMAT = r16f
        }
        final = SHADER.ssao_blur {
            img = IN
            ao = PASS.ao
            depth = AUX.depth
            normal = AUX.normal
            depth_tolerance = PARAM.depth_tolerance
            DEFINE.BLUR = PARAM.blur
            DEFINE.OUTPUT = PARAM.output
            OUT.FORMAT = IN
        }
    }
    OUT = final
}
