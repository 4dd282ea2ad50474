// View-space reconstruction from a projection's inverse, shared by the G-buffer
// effects (shaders/ssao.wgsl, ssao_blur.wgsl, fog.wgsl, outline_detect.wgsl):
// `#include "lib/view.wgsl"`.

// The view-space point of the pixel at `uv` (0..1, y down) and NDC depth `z`.
fn lib_unproject(inv_proj: mat4x4<f32>, uv: vec2<f32>, z: f32) -> vec3<f32> {
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, z, 1.0);
    let h = inv_proj * ndc;
    return h.xyz / h.w;
}

// View-space position of the surface at `uv` with linear depth `d`: the point of
// the pixel's ray (through NDC depths 0.25 and 0.75, finite for standard,
// reversed, infinite-far, [-1, 1] and orthographic projections) whose coordinate
// along the view axis is d. The view axis points to +z or -z depending on the
// camera (sign of z of a point inside the frustum); with the identity matrices of
// a run without a renderer, P = (ndc.x, ndc.y, d).
fn lib_view_pos(inv_proj: mat4x4<f32>, uv: vec2<f32>, d: f32) -> vec3<f32> {
    let a = lib_unproject(inv_proj, uv, 0.25);
    let b = lib_unproject(inv_proj, uv, 0.75);
    let s = select(-1.0, 1.0, a.z >= 0.0);
    let t = (s * d - a.z) / (b.z - a.z);
    return a + t * (b - a);
}
