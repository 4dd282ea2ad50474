// outline_detect: edges of the G-buffer between neighbouring pixels (used by the
// `outline` effect; the maths is documented in effects/outline.fx).
//
// For the pixel p and each 4-neighbour q (inside the image), with P, Q their
// view-space positions (reconstructed from depth with inv_proj) and n_p, n_q their
// normals, the pair is an edge when
//   depth:   max(|dot(Q - P, n_p)|, |dot(Q - P, n_q)|) > depth_threshold * min(d_p, d_q)
//            (distance off each other's tangent plane, relative to depth: 0 on any
//            plane, however slanted; a zero normal falls back to |d_q - d_p|)
//   normal:  dot(n_p, n_q) < cos(normal_threshold)
//   or exactly one of the two has geometry (depth > 0 and finite).
// Output (rgba16f): x = 1 when p is on the near side of an edge with some neighbour
// (d_p <= d_q; a pixel without geometry counts as infinitely far), else 0: the
// outline, one pixel wide, on the silhouette of the nearer surface (both pixels of
// a pair at equal depth). y = the edges of p as bits: 1 left, 2 right, 4 up, 8 down.
@group(0) @binding(0) var depth: texture_2d<f32>;
@group(0) @binding(1) var normal: texture_2d<f32>;

struct Params {
    depth_threshold: f32,  // @default(0.1) @range(0, 1000000) distance off the neighbour's tangent plane, relative to depth, that makes an edge
    normal_threshold: f32, // @default(30) @range(0, 180) angle in degrees between the normals that makes an edge
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/view.wgsl"

fn unit(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    return select(vec3<f32>(0.0), v / l, l > 1e-6);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    let dp = textureLoad(depth, p, 0).r;
    let vp = lib_has_geometry(dp);
    let np = unit(textureLoad(normal, p, 0).xyz);
    let P = lib_texel_view_pos(params.inv_proj, p, sizef, dp);
    let cos_t = cos(radians(params.normal_threshold));
    let offsets = array<vec2<i32>, 4>(vec2<i32>(-1, 0), vec2<i32>(1, 0), vec2<i32>(0, -1), vec2<i32>(0, 1));
    var mark = 0.0;
    var flags = 0u;
    for (var k = 0; k < 4; k++) {
        let q = p + offsets[k];
        if (!lib_inside(q, size)) {
            continue;
        }
        let dq = textureLoad(depth, q, 0).r;
        let vq = lib_has_geometry(dq);
        var edge = false;
        var near = false;
        if (vp && vq) {
            let nq = unit(textureLoad(normal, q, 0).xyz);
            let Q = lib_texel_view_pos(params.inv_proj, q, sizef, dq);
            var off = abs(dq - dp);
            if (dot(np, np) > 0.0 && dot(nq, nq) > 0.0) {
                off = max(abs(dot(Q - P, np)), abs(dot(Q - P, nq)));
                edge = dot(np, nq) < cos_t;
            }
            edge = edge || off > params.depth_threshold * min(dp, dq);
            near = dp <= dq;
        } else if (vp != vq) {
            edge = true;
            near = vp;
        }
        if (edge) {
            flags |= 1u << u32(k);
            if (near) {
                mark = 1.0;
            }
        }
    }
    return vec4<f32>(mark, f32(flags), 0.0, 1.0);
}
