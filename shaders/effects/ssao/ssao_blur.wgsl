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

#include "lib/view.wgsl"

fn blurred(p: vec2<i32>) -> f32 {
#if BLUR
    return lib_gbuffer_blur(ao, depth, normal, params.inv_proj, p, params.depth_tolerance).r;
#else
    return textureLoad(ao, p, 0).r;
#endif
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let a = blurred(p);
#if OUTPUT == 1
    return vec4<f32>(a, a, a, 1.0);
#else
    let c = textureLoad(img, p, 0);
    return vec4<f32>(c.rgb * a, c.a);
#endif
}
