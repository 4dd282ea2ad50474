// lib_gbuffer_blur (lib/view.wgsl) as a compute pass's workgroup computes it:
// the compute entry points of shaders/effects/ssao/ssao_blur.wgsl and
// shaders/effects/ssgi/ssgi_out.wgsl. `#include "lib/view.wgsl"` first, then
// `#include "lib/gbuffer_blur_tile.wgsl"`, and run the entry point at
// `@workgroup_size(16, 8, 1)` (LIB_TILE_W x LIB_TILE_H).
//
// The workgroup's 16x8 pixels read the 5x5 neighbourhoods of a 20x12 tile.
// lib_gbuffer_tile_stage loads each of its texels once (depth, normal, the
// value blurred) and reconstructs its view-space position and unit normal once
// (the fragment blur does both 24 times per pixel, once per neighbour);
// lib_gbuffer_tile_blur then weighs the 5x5 neighbourhood from workgroup memory
// with lib_gbuffer_blur's weights, in its order: the same value.

const LIB_TILE_W: i32 = 16;
const LIB_TILE_H: i32 = 8;
const LIB_TILE_SPAN: i32 = LIB_TILE_W + 4;
const LIB_TILE_TEXELS: i32 = (LIB_TILE_W + 4) * (LIB_TILE_H + 4);

// Per tile texel: view-space position (w = 1 where the texel holds a surface,
// 0 without one or outside the image), unit normal (w = linear depth), and the
// value blurred. 3 x 240 x 16 bytes = 11.25 KiB.
var<workgroup> lib_tile_pos: array<vec4<f32>, 240>;
var<workgroup> lib_tile_normal: array<vec4<f32>, 240>;
var<workgroup> lib_tile_src: array<vec4<f32>, 240>;

// Loads the tile around the workgroup's pixels (`origin` its first) into
// workgroup memory; `index` is the invocation's local_invocation_index. The
// caller puts a workgroupBarrier after it.
fn lib_gbuffer_tile_stage(src: texture_2d<f32>, depth: texture_2d<f32>, normal: texture_2d<f32>, inv_proj: mat4x4<f32>, origin: vec2<i32>, index: u32) {
    let size = vec2<i32>(textureDimensions(depth));
    let sizef = vec2<f32>(size);
    for (var i = i32(index); i < LIB_TILE_TEXELS; i += LIB_TILE_W * LIB_TILE_H) {
        let q = origin - 2 + vec2<i32>(i % LIB_TILE_SPAN, i / LIB_TILE_SPAN);
        var pos = vec4<f32>(0.0);
        var n = vec4<f32>(0.0);
        var v = vec4<f32>(0.0);
        if (lib_inside(q, size)) {
            let d = textureLoad(depth, q, 0).r;
            let n_raw = textureLoad(normal, q, 0).xyz;
            v = textureLoad(src, q, 0);
            if (lib_has_geometry(d) && length(n_raw) > 1e-6) {
                pos = vec4<f32>(lib_texel_view_pos(inv_proj, q, sizef, d), 1.0);
                n = vec4<f32>(normalize(n_raw), d);
            }
        }
        lib_tile_pos[i] = pos;
        lib_tile_normal[i] = n;
        lib_tile_src[i] = v;
    }
}

// lib_gbuffer_blur at the workgroup's pixel `l` (local_invocation_id.xy), from
// the staged tile.
fn lib_gbuffer_tile_blur(l: vec2<i32>, tol_rel: f32) -> vec4<f32> {
    let c = (l.y + 2) * LIB_TILE_SPAN + l.x + 2;
    let centre = lib_tile_src[c];
    let P = lib_tile_pos[c];
    if (P.w == 0.0) {
        return centre;
    }
    let n = lib_tile_normal[c].xyz;
    let tol = tol_rel * lib_tile_normal[c].w;
    var sum = centre;
    var total = 1.0;
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let t = c + dy * LIB_TILE_SPAN + dx;
            let Q = lib_tile_pos[t];
            if ((dx == 0 && dy == 0) || Q.w == 0.0) {
                continue;
            }
            let e = dot(Q.xyz - P.xyz, n) / tol;
            let facing = max(dot(n, lib_tile_normal[t].xyz), 0.0);
            let f2 = facing * facing;
            let f4 = f2 * f2;
            let ws = select(1.0, 0.5, abs(dx) == 2) * select(1.0, 0.5, abs(dy) == 2);
            let w = ws * exp(-e * e) * f4 * f4;
            sum += w * lib_tile_src[t];
            total += w;
        }
    }
    return sum / total;
}
