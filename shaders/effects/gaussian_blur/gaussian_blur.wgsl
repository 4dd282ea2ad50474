// gauss: one direction of a separable Gaussian blur at the input's resolution (the
// output has the input's size). Used by `gaussian_blur` and `sharpen`.
//
// Radius r = (ksize - 1) / 2 with ksize = round(6 sigma + 1) | 1 (OpenCV's rule for
// 8-bit images, round half to even); weights exp(-i^2 / (2 sigma^2)) for i in
// [-r, r], normalised to a sum of 1. The border is replicated (clamp-to-edge).
//
// Defines:
//   VERTICAL = 0: horizontal (default); 1: vertical.
//   EXACT = 0: two texels per bilinear tap at the weighted position between them
//              (r + 1 fetches; the default, fastest);
//           1: one textureLoad per texel (2r + 1 fetches; no dependence on the
//              sampler's sub-texel precision).
//   UNSHARP = 1: unsharp mask instead of a blur: `orig + amount * (orig - blur)`
//              where |orig - blur| >= threshold (per channel), clamped at 0,
//              alpha of `orig` (`sharpen` runs its vertical blur this way,
//              saving a pass).
#define VERTICAL 0
#define EXACT 0
#define UNSHARP 0

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;
#if UNSHARP
@group(0) @binding(3) var orig: texture_2d<f32>;
#endif

struct Params {
    sigma: f32, // @default(2) @range(0.1, 128) standard deviation in pixels
#if UNSHARP
    amount: f32,    // @default(1) @range(0, 20) strength: orig + amount * (orig - blur)
    threshold: f32, // @default(0) @range(0, 1) per-channel differences below this are not sharpened
#endif
    img_size: vec2<f32>,
    img_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/gauss_pairs.wgsl"

fn radius(sigma: f32) -> i32 {
    // WGSL round() rounds half to even, like OpenCV's cvRound.
    let ksize = i32(round(sigma * 6.0 + 1.0)) | 1;
    return (ksize - 1) / 2;
}

// The blur at `p` minus the centre texel `c`: weighted differences from the centre
// are summed, so that a flat area gives exactly 0 (and the blur exactly `c`) even
// where the target format rounds towards zero.
fn blur_delta(p: vec2<i32>, c: vec4<f32>) -> vec4<f32> {
    let r = radius(params.sigma);
    var sum = vec4<f32>(0.0);
    var total = 1.0;
#if EXACT
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;         // w(1)
    var step = q * q2; // w(2) / w(1) = q^3
#if VERTICAL
    let last = i32(params.img_size.y) - 1;
    let k = p.y;
#else
    let last = i32(params.img_size.x) - 1;
    let k = p.x;
#endif
    for (var i = 1; i <= r; i++) {
        let a = max(k - i, 0);
        let b = min(k + i, last);
#if VERTICAL
        let s = textureLoad(img, vec2<i32>(p.x, a), 0) + textureLoad(img, vec2<i32>(p.x, b), 0);
#else
        let s = textureLoad(img, vec2<i32>(a, p.y), 0) + textureLoad(img, vec2<i32>(b, p.y), 0);
#endif
        sum += w * (s - 2.0 * c);
        total += 2.0 * w;
        w *= step;
        step *= q2;
    }
#else
#if VERTICAL
    let dir = vec2<f32>(0.0, params.img_texel.y);
#else
    let dir = vec2<f32>(params.img_texel.x, 0.0);
#endif
    let uv = (vec2<f32>(p) + 0.5) * params.img_texel;
    var g = lib_gauss_pairs(params.sigma);
    for (var i = 1; i <= r; i += 2) {
        let w = lib_gauss_next_pair(&g, i, r);
        let pair = w.x + w.y;
        // Sampling between texels i and i+1 at this offset weights them w(i) : w(i+1);
        // clamp-to-edge makes texels past the border replicate the edge.
        let offset = f32(i) + w.y / max(pair, 1e-30);
        let s = textureSampleLevel(img, img_sampler, uv + offset * dir, 0.0)
              + textureSampleLevel(img, img_sampler, uv - offset * dir, 0.0);
        sum += pair * (s - 2.0 * c);
        total += 2.0 * pair;
    }
#endif
    return sum / total;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
#if UNSHARP
    let o = textureLoad(orig, p, 0);
    // The blur's centre is `img` (the horizontal blur), not `orig`.
    let c = textureLoad(img, p, 0);
    let d = o.rgb - (c.rgb + blur_delta(p, c).rgb);
    let keep = select(vec3<f32>(0.0), vec3<f32>(1.0), abs(d) >= vec3<f32>(params.threshold));
    return vec4<f32>(max(o.rgb + params.amount * d * keep, vec3<f32>(0.0)), o.a);
#else
    let c = textureLoad(img, p, 0);
    return c + blur_delta(p, c);
#endif
}
