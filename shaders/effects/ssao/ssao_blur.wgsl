// ssao_blur: depth- and normal-aware (bilateral) blur of the raw AO from
// shaders/effects/ssao/ssao_occlusion.wgsl (lib_gbuffer_blur of lib/view.wgsl), then the composite (used
// by the `ssao` effect).
//
// Over the 5x5 neighbourhood q of the pixel p (border pixels outside the image are
// skipped), with spatial weights w_s = a(dx) a(dy), a = [0.5, 1, 1, 1, 0.5] (every
// phase of the 4x4 rotation noise gets the same total weight, so the noise pattern
// averages out on a flat surface):
//   w_q = w_s * exp(-(dot(Q - P, n_p) / (depth_tolerance * d_p))^2) * max(dot(n_p, n_q), 0)^8
// i.e. a tap counts when it lies on the tangent plane of p (a step in depth, measured
// relative to p's depth, cuts it off; a continuous slanted or grazing surface does
// not) and faces the same way. Taps without geometry are skipped.
//   ao = sum(w_q ao_q) / sum(w_q)   (the centre always has weight 1)
//   BLUR = 0: no blur, ao = ao_p.
// OUTPUT = 0: out = vec4(img.rgb * ao, img.a); OUTPUT = 1: out = vec4(ao, ao, ao, 1).
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, the compute
// pass, runs under compute execution (`auto` on GPUs) wherever the output can
// be a storage texture (rgba16f); `fs_main` is drawn elsewhere (an 8-bit sRGB
// output), and under fragment execution (`auto` on CPU adapters:
// `// @execution(compute)`, as on lavapipe cs_main saves no CPU,
// docs/architecture.md). cs_main's workgroup
// of 16x8 pixels stages the 20x12 texels their neighbourhoods cover once,
// view-space positions and normals reconstructed there
// (lib/gbuffer_blur_tile.wgsl): 1.9 texels loaded and unprojected per pixel
// instead of 25. Same weights in the same order as fs_main: measured on
// lavapipe 7.9e-4 relative (the rgba16f output against fs_main's at
// rgba32f, tests/execution.rs): the rgba16f step alone.
#define BLUR 1
#define OUTPUT 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var ao: texture_2d<f32>;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var normal: texture_2d<f32>;

struct Params {
    depth_tolerance: f32, // @default(0.02) @range(0.00001, 10) plane distance (relative to depth) where a tap's weight falls to 1/e
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(4) var<uniform> params: Params;
@group(0) @binding(5) var out: texture_storage_2d<rgba16float, write>;

#include "lib/view.wgsl"
#include "lib/gbuffer_blur_tile.wgsl"

fn blurred(p: vec2<i32>) -> f32 {
#if BLUR
    return lib_gbuffer_blur(ao, depth, normal, params.inv_proj, p, params.depth_tolerance).r;
#else
    return textureLoad(ao, p, 0).r;
#endif
}

// The output at `p` with occlusion `a`.
fn composite(p: vec2<i32>, a: f32) -> vec4<f32> {
#if OUTPUT == 1
    return vec4<f32>(a, a, a, 1.0);
#else
    let c = textureLoad(img, p, 0);
    return vec4<f32>(c.rgb * a, c.a);
#endif
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    return composite(p, blurred(p));
}

// @execution(compute)
@compute @workgroup_size(16, 8, 1)
fn cs_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) index: u32,
) {
    let origin = vec2<i32>(group.xy) * vec2<i32>(LIB_TILE_W, LIB_TILE_H);
    let l = vec2<i32>(local.xy);
    let p = origin + l;
#if BLUR
    lib_gbuffer_tile_stage(ao, depth, normal, params.inv_proj, origin, index);
    workgroupBarrier();
#endif
    if (any(p >= vec2<i32>(textureDimensions(out)))) {
        return;
    }
#if BLUR
    let a = lib_gbuffer_tile_blur(l, params.depth_tolerance).r;
#else
    let a = textureLoad(ao, p, 0).r;
#endif
    textureStore(out, p, composite(p, a));
}
