// Tangent-space normal mapping for surface shaders: `#include "lib/normal.wgsl"`.
//
// `perturb_normal(n, tangent, ts)` turns a tangent-space normal `ts` (already
// unpacked to -1..1 and scaled, glTF convention: +X along the tangent, i.e. the
// direction of increasing u; +Y along the bitangent; +Z out of the surface) into
// the same space as `n` and `tangent` (view space for SurfaceInput's fields).
//
// `tangent.xyz` is the unit tangent and `tangent.w` (+1 or -1) the handedness:
// bitangent = cross(n, tangent.xyz) * tangent.w. Where w is 0 (a mesh without
// tangents nor texture coordinates) the geometric normal `n` is returned.
//
// Back faces of double-sided materials: SurfaceInput flips `normal` but not
// `tangent`; pass `select(in.tangent, -in.tangent, !in.front_facing)` as the tangent
// so the whole frame (tangent, bitangent and normal) turns round, as glTF does.

fn perturb_normal(n: vec3<f32>, tangent: vec4<f32>, ts: vec3<f32>) -> vec3<f32> {
    // Re-orthogonalise the interpolated tangent against the normal (Gram-Schmidt).
    let t_raw = tangent.xyz - n * dot(n, tangent.xyz);
    let t_len2 = dot(t_raw, t_raw);
    let t = t_raw * inverseSqrt(max(t_len2, 1e-20));
    let b = cross(n, t) * tangent.w;
    let p = t * ts.x + b * ts.y + n * ts.z;
    let p_len2 = dot(p, p);
    let ok = tangent.w != 0.0 && t_len2 > 1e-12 && p_len2 > 1e-12;
    return select(n, p * inverseSqrt(max(p_len2, 1e-20)), ok);
}

// Unpack a normal-map texel (0..1 per channel) to a tangent-space normal with its
// xy scaled by `scale` (glTF `normalTexture.scale`).
fn unpack_normal(texel: vec3<f32>, scale: f32) -> vec3<f32> {
    let v = texel * 2.0 - vec3<f32>(1.0);
    return vec3<f32>(v.xy * scale, v.z);
}
