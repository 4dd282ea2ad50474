// The Gaussian blur along one axis of shaders/effects/glow/blurX.wgsl (VERTICAL = 0) and
// blurY.wgsl (VERTICAL = 1), with the standard deviation in output pixels:
// `#define VERTICAL 0` then `#include "lib/blur_axis.wgsl"`.
//
// Same size as the input: exact normalised Gaussian weights over [-r, r],
// r = ceil(3 sigma), taken two at a time with one bilinear tap (lib/gauss_pairs.wgsl).
//
// Smaller than the input (a downsampling blur, e.g. glow's half-size pass): the
// input is first box-filtered over the texels each output texel covers (2x2
// texels per bilinear fetch at a texel-pair centre, ceil(ratio / 2) fetches per
// axis), then blurred with the exact weights at every output column (row) in
// [-r, r], edge columns (rows) repeated (lib/prefilter.wgsl). Taking the
// bilinear-pair taps at output spacing there would skip input columns (rows) and
// leave stripes in the halo.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(4) @range(0.1, 256) standard deviation in output pixels
    out_texel: vec2<f32>,
    out_size: vec2<f32>,
    img_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "prefilter.wgsl"
#include "gauss_pairs.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
#if VERTICAL
    let axis = vec2<f32>(0.0, 1.0);
    let dir = vec2<f32>(0.0, params.out_texel.y);
#else
    let axis = vec2<f32>(1.0, 0.0);
    let dir = vec2<f32>(params.out_texel.x, 0.0);
#endif
    let ratio = params.img_size / params.out_size;
    if (any(ratio > vec2<f32>(1.0))) {
        return lib_downsampling_blur(
            img, img_sampler, pos.xy, axis, params.sigma,
            params.out_texel, params.out_size, params.img_size,
        );
    }
    let r = i32(ceil(3.0 * params.sigma));
    var g = lib_gauss_pairs(params.sigma);
    var sum = textureSampleLevel(img, img_sampler, uv, 0.0);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        let offset = (f32(i) * w.x + f32(i + 1) * w.y) / pair;
        sum += pair * (textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
                     + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0));
        total += 2.0 * pair;
    }
    return sum / total;
}
