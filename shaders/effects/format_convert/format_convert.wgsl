// format_convert: numeric colour conversions (the `format_convert` effect).
//
// DIRECTION 0 rgb_to_ycbcr, 1 ycbcr_to_rgb, 2 linear_to_srgb, 3 srgb_to_linear.
// MATRIX 0 BT.709 (Kr 0.2126, Kb 0.0722), 1 BT.601 (Kr 0.299, Kb 0.114).
// RANGE 0 full (Y' in [0, 1], Cb/Cr centred on 0.5), 1 limited ("video", the 8-bit
//   code values Y 16..235 and C 16..240 centred on 128, divided by 255).
// TRANSFER 0 srgb: the RGB side is linear light, R'G'B' = sRGB OETF(RGB);
//   1 none: the matrix applies to the numbers as they are.
// The sRGB curve is the exact piecewise one, extended to negative values by
// symmetry (f(-x) = -f(x)) and to values above 1 by the same formula.
// Alpha is passed through.
@group(0) @binding(0) var img: texture_2d<f32>;

#define DIRECTION 0
#define MATRIX 0
#define RANGE 0
#define TRANSFER 0

#if MATRIX == 0
const KR: f32 = 0.2126;
const KB: f32 = 0.0722;
#else
const KR: f32 = 0.299;
const KB: f32 = 0.114;
#endif
const KG: f32 = 1.0 - KR - KB;

fn oetf(c: vec3<f32>) -> vec3<f32> {
    let x = abs(c);
    let e = select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, x * 12.92, x <= vec3<f32>(0.0031308));
    return sign(c) * e;
}

fn eotf(c: vec3<f32>) -> vec3<f32> {
    let x = abs(c);
    let l = select(pow((x + 0.055) / 1.055, vec3<f32>(2.4)), x / 12.92, x <= vec3<f32>(0.04045));
    return sign(c) * l;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
#if DIRECTION == 0
#if TRANSFER == 0
    let e = oetf(c.rgb);
#else
    let e = c.rgb;
#endif
    let y = KR * e.r + KG * e.g + KB * e.b;
    let pb = (e.b - y) / (2.0 * (1.0 - KB));
    let pr = (e.r - y) / (2.0 * (1.0 - KR));
#if RANGE == 0
    return vec4<f32>(y, pb + 0.5, pr + 0.5, c.a);
#else
    return vec4<f32>((16.0 + 219.0 * y) / 255.0, (128.0 + 224.0 * pb) / 255.0, (128.0 + 224.0 * pr) / 255.0, c.a);
#endif
#elif DIRECTION == 1
#if RANGE == 0
    let y = c.r;
    let pb = c.g - 0.5;
    let pr = c.b - 0.5;
#else
    let y = (255.0 * c.r - 16.0) / 219.0;
    let pb = (255.0 * c.g - 128.0) / 224.0;
    let pr = (255.0 * c.b - 128.0) / 224.0;
#endif
    let r = y + 2.0 * (1.0 - KR) * pr;
    let b = y + 2.0 * (1.0 - KB) * pb;
    let g = (y - KR * r - KB * b) / KG;
#if TRANSFER == 0
    return vec4<f32>(eotf(vec3<f32>(r, g, b)), c.a);
#else
    return vec4<f32>(r, g, b, c.a);
#endif
#elif DIRECTION == 2
    return vec4<f32>(oetf(c.rgb), c.a);
#else
    return vec4<f32>(eotf(c.rgb), c.a);
#endif
}
