// blurY: vertical Gaussian blur with the standard deviation in output pixels.
//
// Same size as the input: exact normalised Gaussian weights over [-r, r],
// r = ceil(3 sigma), taken two at a time with one bilinear tap.
//
// Smaller than the input (a downsampling blur, e.g. glow's half-size pass): the
// input is first box-filtered over the texels each output texel covers (2x2
// texels per bilinear fetch at a texel-pair centre, ceil(ratio / 2) fetches per
// axis), then blurred with the exact weights at every output row in [-r, r]
// (edge rows repeated). Taking the bilinear-pair taps at output spacing there
// would skip input rows and leave stripes in the halo.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(4) @range(0.1, 256) standard deviation in output pixels
    out_texel: vec2<f32>,
    out_size: vec2<f32>,
    img_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/prefilter.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let ratio = params.img_size / params.out_size;
    if (any(ratio > vec2<f32>(1.0))) {
        return lib_downsampling_blur(
            img, img_sampler, pos.xy, vec2<f32>(0.0, 1.0), params.sigma,
            params.out_texel, params.out_size, params.img_size,
        );
    }
    let dir = vec2<f32>(0.0, params.out_texel.y);
    let r = i32(ceil(3.0 * params.sigma));
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;         // w(1)
    var step = q * q2; // w(2) / w(1) = q^3
    var sum = textureSampleLevel(img, img_sampler, uv, 0.0);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w1 = w;
        var w2 = w1 * step;
        if (i + 1 > r) {
            w2 = 0.0;
        }
        let pair = w1 + w2;
        let offset = (f32(i) * w1 + f32(i + 1) * w2) / pair;
        sum += pair * (textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
                     + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0));
        total += 2.0 * pair;
        // Advance two steps: w(i+2) = w(i+1) * q^(2i+3).
        w = w2 * step * q2;
        step = step * q2 * q2;
    }
    return sum / total;
}
