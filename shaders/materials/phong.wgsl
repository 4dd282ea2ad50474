// Phong, the seed paper's lighting model, energy-normalised.
//
// With ndl = max(n.l, 0), r = reflect(-l, n) the mirror direction of the light
// and p = specular_power:
//
//   diffuse  = light * ndl / pi
//   specular = light * ndl * F0 * (p + 2) / (2 pi) * max(r.v, 0)^p
//
// where F0 is the surface's specular colour (SurfaceOutput.specular). The
// (p + 2) / (2 pi) factor makes the lobe reflect the same energy whatever its
// width, so a higher power gives a smaller, brighter highlight. The surface's
// roughness is not used (the power sets the highlight size instead).

#include "lib/brdf.wgsl"

struct LightingParams {
    specular_power: f32, // @default(32) @range(1, 4096) the paper's SPECULAR_POWER: highlight sharpness
}

fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput {
    let n = in.normal;
    let l = in.light_dir;
    let ndl = max(dot(n, l), 0.0);
    let p = params.specular_power;
    let rdv = max(dot(reflect(-l, n), in.view_dir), 0.0);
    let lobe = (p + 2.0) / (2.0 * FX_PI) * pow(rdv, p);
    let diffuse = in.light * (ndl * brdf_lambert());
    let specular = in.light * ndl * in.specular * lobe;
    return LightingOutput(diffuse, specular);
}
