// pencil_blur: one direction of the separable Gaussian blur of the `pencil` effect.
// Horizontal (default): blurs the Rec.709 luma of `img`'s rgb; VERTICAL = 1: blurs
// `img`'s red channel (the horizontal result). Writes the blurred value in .r.
//
// Same taps as blurX/blurY: exact normalised Gaussian weights over [-r, r], r =
// ceil(3 s), taken two at a time with one bilinear tap (lib/gauss_pairs.wgsl),
// sampled at the output's resolution (a smaller output also downsamples). The luma
// is linear in the channels, so the luma of a bilinear tap is the bilinear tap of
// the luma. s = sigma * scale is the standard deviation in output pixels: `sigma` is
// given in pixels of the effect input and `scale` is the pass's OUT.SCALE.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(5) @range(0.1, 256) standard deviation in pixels of the effect input
    scale: f32, // @default(1) @range(0.01, 1) the pass's OUT.SCALE (output pixels per input pixel)
    out_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#define VERTICAL 0

#include "lib/gauss_pairs.wgsl"

fn tap(uv: vec2<f32>) -> f32 {
    let c = textureSampleLevel(img, img_sampler, uv, 0.0);
#if VERTICAL
    return c.r;
#else
    return dot(c.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
#endif
}

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
#if VERTICAL
    let dir = vec2<f32>(0.0, params.out_texel.y);
#else
    let dir = vec2<f32>(params.out_texel.x, 0.0);
#endif
    let sigma = params.sigma * params.scale;
    let r = i32(ceil(3.0 * sigma));
    var g = lib_gauss_pairs(sigma);
    var sum = tap(uv);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        let offset = (f32(i) * w.x + f32(i + 1) * w.y) / pair;
        sum += pair * (tap(uv + offset * dir) + tap(uv - offset * dir));
        total += 2.0 * pair;
    }
    let y = sum / total;
    return vec4<f32>(y, y, y, 1.0);
}
