// ssgi_out: spatial denoising of the accumulated indirect light of the `ssgi`
// effect (shaders/effects/ssgi/ssgi_accum.wgsl) and the composite (effects/ssgi.fx has the
// method in words).
//
// Over the 5x5 neighbourhood q of the pixel p (neighbours outside the image or
// without geometry are skipped), the weights w_q of lib_gbuffer_blur
// (lib/view.wgsl, also ssao's blur): [0.5 1 1 1 0.5] per axis (every phase
// of the 4x4 direction pattern of shaders/effects/ssgi/ssgi_trace.wgsl weighs the same, so the
// pattern cancels on a flat surface), times
//   exp(-(dot(Q - P, n_p) / (depth_tolerance * d_p))^2) * max(dot(n_p, n_q), 0)^8
// (taps off p's tangent plane or facing another way do not count);
//   gi = sum(w_q gi_q) / sum(w_q)   (BLUR = 0: gi = gi_p)
// The receiver's added radiance is intensity * albedo(p) * gi (gi = E / pi, the
// albedo from AUX.albedo: the diffuse colour, 0 for metals).
// OUTPUT = 0: out = vec4(img.rgb + added, img.a); OUTPUT = 1: out = vec4(added, 1).
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, the compute
// pass, runs under compute execution (`auto` on GPUs) wherever the output can
// be a storage texture (rgba16f); `fs_main` is drawn elsewhere (an 8-bit sRGB
// output), and under fragment execution (`auto` on CPU adapters:
// `// @execution(compute)`, as on lavapipe cs_main saves no CPU,
// docs/architecture.md). cs_main's workgroup
// of 16x8 pixels stages the 20x12 texels their neighbourhoods cover once,
// view-space positions and normals reconstructed there
// (lib/gbuffer_blur_tile.wgsl, as ssao's blur): 1.9 texels loaded and
// unprojected per pixel instead of 25. Same weights in the same order as
// fs_main: measured on lavapipe 7.1e-4 relative (the
// rgba16f output against fs_main's at rgba32f, tests/execution.rs): the
// rgba16f step alone.
#define BLUR 1
#define OUTPUT 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var gi: texture_2d<f32>;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var normal: texture_2d<f32>;
@group(0) @binding(4) var albedo: texture_2d<f32>;

struct Params {
    intensity: f32,       // @default(1) @range(0, 100) scales the added bounce (1: physically based)
    depth_tolerance: f32, // @default(0.02) @range(0.00001, 10) blur: plane distance (relative to depth) where a tap's weight falls to 1/e
    inv_proj: mat4x4<f32>,
}
@group(0) @binding(5) var<uniform> params: Params;
@group(0) @binding(6) var out: texture_storage_2d<rgba16float, write>;

#include "lib/view.wgsl"
#include "lib/gbuffer_blur_tile.wgsl"

fn blurred(p: vec2<i32>) -> vec3<f32> {
#if BLUR
    return lib_gbuffer_blur(gi, depth, normal, params.inv_proj, p, params.depth_tolerance).rgb;
#else
    return textureLoad(gi, p, 0).rgb;
#endif
}

// The output at `p` with the (blurred) indirect light `g`.
fn composite(p: vec2<i32>, g: vec3<f32>) -> vec4<f32> {
    let added = params.intensity * textureLoad(albedo, p, 0).rgb * g;
#if OUTPUT == 1
    return vec4<f32>(added, 1.0);
#else
    let c = textureLoad(img, p, 0);
    return vec4<f32>(c.rgb + added, c.a);
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
    lib_gbuffer_tile_stage(gi, depth, normal, params.inv_proj, origin, index);
    workgroupBarrier();
#endif
    if (any(p >= vec2<i32>(textureDimensions(out)))) {
        return;
    }
#if BLUR
    let g = lib_gbuffer_tile_blur(l, params.depth_tolerance).rgb;
#else
    let g = textureLoad(gi, p, 0).rgb;
#endif
    textureStore(out, p, composite(p, g));
}
