// View-space reconstruction from a projection's inverse and G-buffer neighbourhood
// sampling, shared by the G-buffer effects (shaders/effects/ssao/ssao_occlusion.wgsl, ssao_blur.wgsl,
// fog.wgsl, outline_detect.wgsl, ssgi_*.wgsl): `#include "lib/view.wgsl"`.

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

// The sign of z along the view axis (+1 or -1): turns a view-space z into a
// linear depth (the z of a point inside the frustum, as in lib_view_pos).
fn lib_forward_sign(inv_proj: mat4x4<f32>) -> f32 {
    return select(-1.0, 1.0, lib_unproject(inv_proj, vec2<f32>(0.5), 0.25).z >= 0.0);
}

// A view-space normal turned against the view ray of the pixel at `uv`.
fn lib_facing_camera(inv_proj: mat4x4<f32>, n: vec3<f32>, uv: vec2<f32>) -> vec3<f32> {
    let ray = lib_unproject(inv_proj, uv, 0.75) - lib_unproject(inv_proj, uv, 0.25);
    return select(n, -n, dot(n, ray) > 0.0);
}

// View-space position of the centre of texel `p` of a G-buffer of `size` texels,
// with linear depth `d` (lib_view_pos at uv = (p + 0.5) / size).
fn lib_texel_view_pos(inv_proj: mat4x4<f32>, p: vec2<i32>, size: vec2<f32>, d: f32) -> vec3<f32> {
    return lib_view_pos(inv_proj, (vec2<f32>(p) + 0.5) / size, d);
}

// Whether a G-buffer depth holds geometry: > 0 and finite (0, infinite and NaN are
// the renderer's "nothing here").
fn lib_has_geometry(d: f32) -> bool {
    return d > 0.0 && d < 3.0e38;
}

// Whether a G-buffer texel holds a surface: geometry and a normal of non-zero,
// non-NaN length.
fn lib_has_surface(d: f32, n: vec3<f32>) -> bool {
    return lib_has_geometry(d) && length(n) > 1e-6;
}

// Whether the neighbour `q` lies inside an image of `size` texels (neighbours
// outside are skipped, not clamped).
fn lib_inside(q: vec2<i32>, size: vec2<i32>) -> bool {
    return all(q >= vec2<i32>(0)) && all(q < size);
}

// The 5x5 depth- and normal-aware blur of the G-buffer effects (shaders/effects/ssao/ssao_blur.wgsl,
// ssgi_out.wgsl): `src` (all four channels) at pixel p, over the neighbours q
// inside the image with geometry (depth and a non-zero normal), weighted by
//   a(dx) a(dy) * exp(-(dot(Q - P, n) / (tol_rel * d))^2) * max(dot(n, n_q), 0)^8
// with a = [0.5, 1, 1, 1, 0.5] (every phase of a 4x4 pattern gets the same total
// weight, so the pattern cancels on a flat surface), P, n, d the pixel's
// view-space position, unit normal and depth and Q, n_q the neighbour's: a
// neighbour off the pixel's tangent plane (by tol_rel * d view-space units for
// 1/e) or facing another way does not count. The centre weighs 1; a pixel without
// geometry keeps its value.
fn lib_gbuffer_blur(src: texture_2d<f32>, depth: texture_2d<f32>, normal: texture_2d<f32>, inv_proj: mat4x4<f32>, p: vec2<i32>, tol_rel: f32) -> vec4<f32> {
    let centre = textureLoad(src, p, 0);
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    let d = textureLoad(depth, p, 0).r;
    let n_raw = textureLoad(normal, p, 0).xyz;
    if (!lib_has_geometry(d) || !(length(n_raw) > 1e-6)) {
        return centre;
    }
    let n = normalize(n_raw);
    let P = lib_texel_view_pos(inv_proj, p, sizef, d);
    let tol = tol_rel * d;
    var sum = centre;
    var total = 1.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let q = p + vec2<i32>(dx, dy);
            if ((dx == 0 && dy == 0) || !lib_inside(q, size)) {
                continue;
            }
            let dq = textureLoad(depth, q, 0).r;
            let nq = textureLoad(normal, q, 0).xyz;
            if (!lib_has_geometry(dq) || !(length(nq) > 1e-6)) {
                continue;
            }
            let e = dot(lib_texel_view_pos(inv_proj, q, sizef, dq) - P, n) / tol;
            let facing = max(dot(n, normalize(nq)), 0.0);
            let f2 = facing * facing;
            let f4 = f2 * f2;
            let ws = select(1.0, 0.5, abs(dx) == 2) * select(1.0, 0.5, abs(dy) == 2);
            let w = ws * exp(-e * e) * f4 * f4;
            sum += w * textureLoad(src, q, 0);
            total += w;
        }
    }
    return sum / total;
}
