// bloomUp: one level of bloom's upsample chain. `low` (the next coarser level, about
// half this output's size) is upsampled and combined with `base`, which has the
// output's size:
//   FINAL = 0:  out = mix(base, tent(low), radius)      (energy-preserving)
//   FINAL = 1:  out = base + intensity * box(low)        (alpha of base kept)
// tent: 3x3 tent filter, weights [1 2 1; 2 4 2; 1 2 1] / 16, bilinear taps one
// `low` texel apart. box: the mean of 4 bilinear taps at (+-0.5, +-0.5) `low`
// texels (a quadratic B-spline-like kernel), used for the last, full-size step
// where 9 taps per pixel would cost twice as much.
#define FINAL 0

@group(0) @binding(0) var base: texture_2d<f32>;
@group(0) @binding(1) var low: texture_2d<f32>;
@group(0) @binding(2) var low_sampler: sampler;

struct Params {
#if FINAL
    intensity: f32, // @default(0.5) @range(0, 100) strength of the bloom added to the image
#else
    radius: f32,    // @default(0.7) @range(0, 1) weight of the coarser level: larger spreads wider
#endif
    low_texel: vec2<f32>,
}
@group(0) @binding(3) var<uniform> params: Params;

fn tap(uv: vec2<f32>, dx: f32, dy: f32) -> vec3<f32> {
    return textureSampleLevel(low, low_sampler, uv + vec2<f32>(dx, dy) * params.low_texel, 0.0).rgb;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let b = textureLoad(base, vec2<i32>(pos.xy), 0);
#if FINAL
    let box = (tap(uv, -0.5, -0.5) + tap(uv, 0.5, -0.5) + tap(uv, -0.5, 0.5) + tap(uv, 0.5, 0.5)) * 0.25;
    return vec4<f32>(b.rgb + params.intensity * box, b.a);
#else
    let tent = (tap(uv, -1.0, -1.0) + tap(uv, 1.0, -1.0) + tap(uv, -1.0, 1.0) + tap(uv, 1.0, 1.0)
              + 2.0 * (tap(uv, 0.0, -1.0) + tap(uv, -1.0, 0.0) + tap(uv, 1.0, 0.0) + tap(uv, 0.0, 1.0))
              + 4.0 * tap(uv, 0.0, 0.0)) * (1.0 / 16.0);
    return vec4<f32>(mix(b.rgb, tent, params.radius), 1.0);
#endif
}
