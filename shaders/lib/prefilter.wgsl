// Box prefilter and downsampling blur of the downsampling passes (shaders/effects/glow/blurX.wgsl,
// blurY.wgsl): `#include "lib/prefilter.wgsl"`.

// The mean of the input texels under the output texel at `uv` (0..1): `m` bilinear
// fetches per axis, each at a texel-pair centre (one fetch averages 2x2 texels),
// spaced two input texels apart (`spacing` = 2 / input size).
fn lib_box_prefilter(
    img: texture_2d<f32>,
    img_sampler: sampler,
    uv: vec2<f32>,
    spacing: vec2<f32>,
    m: vec2<i32>,
) -> vec4<f32> {
    var box = vec4<f32>(0.0);
    for (var j = 0; j < m.y; j++) {
        for (var k = 0; k < m.x; k++) {
            let o = (vec2<f32>(f32(k), f32(j)) - 0.5 * vec2<f32>(m - 1)) * spacing;
            box += textureSampleLevel(img, img_sampler, uv + o, 0.0);
        }
    }
    return box / f32(m.x * m.y);
}

// A downsampling Gaussian blur along `axis` ((1, 0) or (0, 1)) at the output pixel
// centred at `pos` (output pixel coordinates): the input is box-filtered over the
// texels each output texel covers (`lib_box_prefilter`), then blurred with the exact
// weights at every output texel in [-r, r], r = ceil(3 sigma), edge texels repeated.
// Taking bilinear-pair taps at output spacing instead would skip input columns and
// leave stripes in the halo.
fn lib_downsampling_blur(
    img: texture_2d<f32>,
    img_sampler: sampler,
    pos: vec2<f32>,
    axis: vec2<f32>,
    sigma: f32,
    out_texel: vec2<f32>,
    out_size: vec2<f32>,
    img_size: vec2<f32>,
) -> vec4<f32> {
    let ratio = img_size / out_size;
    let m = max(vec2<i32>(ceil(ratio * 0.5 - 1e-4)), vec2<i32>(1));
    let r = i32(ceil(3.0 * sigma));
    let last = dot(out_size, axis) - 1.0;
    // w(i) = q^(i*i) for i = -r..r, advanced by products (no exp per tap):
    // w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (sigma * sigma));
    var w = pow(q, f32(r * r));
    var step = pow(q, f32(1 - 2 * r));
    let q2 = q * q;
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    // One fetch per tap when the ratio is at most 2 per axis (glow's half-size
    // passes): the bilinear fetch at a texel-pair centre is the whole box.
    let single = all(m == vec2<i32>(1));
    let across = pos * (vec2<f32>(1.0) - axis);
    for (var i = -r; i <= r; i++) {
        let along = clamp(floor(dot(pos, axis) + f32(i)), 0.0, last) + 0.5;
        let uv = (across + along * axis) * out_texel;
        var v: vec4<f32>;
        if (single) {
            v = textureSampleLevel(img, img_sampler, uv, 0.0);
        } else {
            v = lib_box_prefilter(img, img_sampler, uv, 2.0 / img_size, m);
        }
        sum += w * v;
        total += w;
        w *= step;
        step *= q2;
    }
    return sum / total;
}
