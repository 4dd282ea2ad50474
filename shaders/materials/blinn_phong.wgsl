// Blinn-Phong, energy-normalised.
//
// With ndl = max(n.l, 0), h = normalize(l + v) the half vector and p = shininess:
//
//   diffuse  = light * ndl / pi
//   specular = light * ndl * F0 * (p + 8) / (8 pi) * max(n.h, 0)^p
//
// where F0 is the surface's specular colour (SurfaceOutput.specular). The
// (p + 8) / (8 pi) factor is the usual normalisation of the Blinn-Phong lobe.
// The surface's roughness is not used.

#include "lib/brdf.wgsl"

struct LightingParams {
    shininess: f32, // @default(64) @range(1, 4096) Blinn-Phong exponent: highlight sharpness
}

fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput {
    let n = in.normal;
    let l = in.light_dir;
    let ndl = max(dot(n, l), 0.0);
    let h = brdf_half_vector(l, in.view_dir);
    let p = params.shininess;
    let lobe = (p + 8.0) / (8.0 * FX_PI) * pow(max(dot(n, h), 0.0), p);
    let diffuse = in.light * (ndl * brdf_lambert());
    let specular = in.light * ndl * in.specular * lobe;
    return LightingOutput(diffuse, specular);
}
