// gauss: one direction of a separable Gaussian blur at the input's resolution
// (output and input have the same size). Used by `gaussian_blur` and `sharpen`.
//
// Radius r = (ksize - 1) / 2 with ksize = round(6 sigma + 1) | 1 (OpenCV's rule for
// 8-bit images); weights exp(-i^2 / (2 sigma^2)) for i in [-r, r], normalised to a
// sum of 1. The border is replicated (clamp-to-edge).
//
// Defines: VERTICAL = 0 (horizontal, default) or 1 (vertical).
//          EXACT = 1 reads every texel with textureLoad (2r + 1 loads);
//          EXACT = 0 takes two texels per bilinear tap (r + 1 taps).
#define VERTICAL 0
#define EXACT 1

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(2) @range(0.1, 128) standard deviation in pixels
    img_size: vec2<f32>,
    img_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

fn radius(sigma: f32) -> i32 {
    // WGSL round() rounds half to even, like OpenCV's cvRound.
    let ksize = i32(round(sigma * 6.0 + 1.0)) | 1;
    return (ksize - 1) / 2;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let r = radius(params.sigma);
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    let p = vec2<i32>(pos.xy);
#if EXACT
#if VERTICAL
    let last = i32(params.img_size.y) - 1;
    let c = p.y;
#else
    let last = i32(params.img_size.x) - 1;
    let c = p.x;
#endif
    var sum = textureLoad(img, p, 0);
    var total = 1.0;
    var w = q;    // w(1)
    var step = q * q2; // w(2) / w(1)
    for (var i = 1; i <= r; i++) {
        let a = max(c - i, 0);
        let b = min(c + i, last);
#if VERTICAL
        let s = textureLoad(img, vec2<i32>(p.x, a), 0) + textureLoad(img, vec2<i32>(p.x, b), 0);
#else
        let s = textureLoad(img, vec2<i32>(a, p.y), 0) + textureLoad(img, vec2<i32>(b, p.y), 0);
#endif
        sum += w * s;
        total += 2.0 * w;
        w *= step;
        step *= q2;
    }
    return sum / total;
#else
#if VERTICAL
    let dir = vec2<f32>(0.0, params.img_texel.y);
#else
    let dir = vec2<f32>(params.img_texel.x, 0.0);
#endif
    let uv = pos.xy * params.img_texel;
    var sum = textureLoad(img, p, 0);
    var total = 1.0;
    var w = q;         // w(1)
    var step = q * q2; // w(2) / w(1) = q^3
    for (var i = 1; i <= r; i += 2) {
        let w1 = w;
        var w2 = w1 * step;
        if (i + 1 > r) {
            w2 = 0.0;
        }
        let pair = w1 + w2;
        let offset = f32(i) + w2 / pair;
        sum += pair * (textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
                     + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0));
        total += 2.0 * pair;
        // Advance two steps: w(i+2) = w(i+1) * q^(2i+3).
        w = w2 * step * q2;
        step = step * q2 * q2;
    }
    return sum / total;
#endif
}
