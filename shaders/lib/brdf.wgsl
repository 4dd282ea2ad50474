// Shared BRDF pieces for lighting shaders: `#include "lib/brdf.wgsl"`.
//
// Conventions: every direction is a unit vector; `ndl`, `ndv`, `ndh` are the
// cosines n.l, n.v, n.h; `alpha` is the GGX width parameter (glTF: the square of
// the perceptual roughness). The functions return BRDF factors only; the caller
// multiplies by the illuminance and the cosine n.l.

// Schlick's Fresnel approximation: F0 + (1 - F0) (1 - cos)^5, with `cos_theta`
// the cosine between the view (or light) direction and the half vector.
fn brdf_fresnel_schlick(f0: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    let m = clamp(1.0 - cos_theta, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
}

// GGX / Trowbridge-Reitz normal distribution:
// D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2).
fn brdf_d_ggx(ndh: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let f = ndh * ndh * (a2 - 1.0) + 1.0;
    return a2 / (FX_PI * f * f);
}

// Height-correlated Smith visibility for GGX (G / (4 n.l n.v) folded in), as in
// glTF 2.0 Appendix B:
// V = 0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2) + n.v sqrt((n.l)^2 (1 - alpha^2) + alpha^2)),
// and 0 where the denominator is 0 (grazing light or view).
fn brdf_v_smith_ggx_correlated(ndl: f32, ndv: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = ndl * sqrt(ndv * ndv * (1.0 - a2) + a2);
    let gl = ndv * sqrt(ndl * ndl * (1.0 - a2) + a2);
    let d = gv + gl;
    return select(0.0, 0.5 / d, d > 0.0);
}

// Lambert's diffuse BRDF for a unit albedo: 1 / pi.
fn brdf_lambert() -> f32 {
    return 1.0 / FX_PI;
}

// The unit half vector between `l` and `v` (n itself would do for l = -v, where
// every term that uses it is 0 anyway; this returns l then instead of NaN).
fn brdf_half_vector(l: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let h = l + v;
    let len2 = dot(h, h);
    return select(l, h * inverseSqrt(len2), len2 > 1e-12);
}
