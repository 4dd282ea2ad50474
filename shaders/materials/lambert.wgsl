// Lambert: a perfectly diffuse surface, no specular reflection.
//
//   diffuse  = light * max(n.l, 0) / pi     (the engine multiplies by the albedo)
//   specular = 0
//
// No parameters. The surface's specular colour and roughness are ignored.

#include "lib/brdf.wgsl"

fn lighting(in: LightingInput) -> LightingOutput {
    let ndl = max(dot(in.normal, in.light_dir), 0.0);
    return LightingOutput(in.light * (ndl * brdf_lambert()), vec3<f32>(0.0));
}
