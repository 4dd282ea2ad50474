// pencil_blur: horizontal Gaussian blur of the Rec.709 luma of `img` (first half of
// the separable blur of the `pencil` effect; the vertical half is blurY).
// Same taps as blurX: exact normalised Gaussian weights over [-r, r],
// r = ceil(3 sigma), taken two at a time with one bilinear tap. The luma is linear
// in the channels, so the luma of a bilinear tap is the bilinear tap of the luma.
// Writes the blurred luma in .r (use a one-channel OUT.FORMAT).
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    sigma: f32, // @default(5) @range(0.1, 256) standard deviation in output pixels
    out_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

fn luma(uv: vec2<f32>) -> f32 {
    return dot(textureSampleLevel(img, img_sampler, uv, 0.0).rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
}

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let dir = vec2<f32>(params.out_texel.x, 0.0);
    let r = i32(ceil(3.0 * params.sigma));
    // w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)); w(i+1) = w(i) * q^(2i+1).
    let q = exp(-0.5 / (params.sigma * params.sigma));
    let q2 = q * q;
    var w = q;         // w(1)
    var step = q * q2; // w(2) / w(1) = q^3
    var sum = luma(uv);
    var total = 1.0;
    for (var i = 1; i <= r; i += 2) {
        let w1 = w;
        var w2 = w1 * step;
        if (i + 1 > r) {
            w2 = 0.0;
        }
        let pair = w1 + w2;
        let offset = (f32(i) * w1 + f32(i + 1) * w2) / pair;
        sum += pair * (luma(uv + offset * dir) + luma(uv - offset * dir));
        total += 2.0 * pair;
        w = w2 * step * q2;
        step = step * q2 * q2;
    }
    let y = sum / total;
    return vec4<f32>(y, y, y, 1.0);
}
