// Cook-Torrance microfacet BRDF, exactly as in glTF 2.0 Appendix B (the
// metallic-roughness model), with the surface's F0 and perceptual roughness:
//
//   alpha = roughness^2
//   F = F0 + (1 - F0) (1 - |v.h|)^5                        (Schlick)
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)        (GGX / Trowbridge-Reitz)
//   V = 0.5 / (ndl sqrt(ndv^2 (1 - alpha^2) + alpha^2)
//            + ndv sqrt(ndl^2 (1 - alpha^2) + alpha^2))     (height-correlated Smith;
//                                                            V = 0 where the denominator is 0)
//   specular = light * ndl * F * D * V
//   diffuse  = light * ndl * (1 - F) / pi                  (the engine multiplies by the albedo)
//
// with ndl = max(n.l, 0) and h = normalize(l + v).
//
// Choices (glTF leaves them open):
// - ndv = max(n.v, 1e-4): a shading normal that faces slightly away from the
//   eye (normal maps, interpolation) keeps a small positive cosine instead of
//   making V undefined; abs(n.v) would light such back-facing normals as if
//   they faced the eye.
// - alpha is clamped to at least 1e-3: roughness 0 would make D a Dirac pulse
//   (infinite at n = h, 0 elsewhere), which a point light would turn into a
//   one-pixel NaN-prone highlight or none at all.
//
// No parameters: everything comes from the surface (SurfaceOutput.specular and
// .roughness).

#include "lib/brdf.wgsl"

fn lighting(in: LightingInput) -> LightingOutput {
    let n = in.normal;
    let l = in.light_dir;
    let v = in.view_dir;
    let h = brdf_half_vector(l, v);
    let ndl = max(dot(n, l), 0.0);
    let ndv = max(dot(n, v), 1e-4);
    let ndh = max(dot(n, h), 0.0);
    let vdh = abs(dot(v, h));
    let alpha = max(in.roughness * in.roughness, 1e-3);
    let f = brdf_fresnel_schlick(in.specular, vdh);
    let d = brdf_d_ggx(ndh, alpha);
    let vis = brdf_v_smith_ggx_correlated(ndl, ndv, alpha);
    let specular = in.light * ndl * f * (d * vis);
    let diffuse = in.light * ndl * (vec3<f32>(1.0) - f) * brdf_lambert();
    return LightingOutput(diffuse, specular);
}
