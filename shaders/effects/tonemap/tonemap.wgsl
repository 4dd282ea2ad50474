// tonemap: maps linear HDR colour to display-referred linear [0, 1]:
//   x = max(in, 0) * 2^exposure
//   OPERATOR = 0 (Reinhard), per channel:
//                             white <= 0: y = x / (1 + x)
//                             white  > 0: y = x (1 + x / white^2) / (1 + x)   (extended: white -> 1)
//   OPERATOR = 1 (ACES, Narkowicz 2015 filmic fit), per channel:
//                             y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//   OPERATOR = 2 (Khronos PBR Neutral, the published specification): on the
//                             colour, hue-preserving; identity below 0.76 (after
//                             the toe offset), then a highlight compression that
//                             desaturates towards white
//   OPERATOR = 3 (AgX, Troy Sobotka's, as in Blender 4): inset matrix, log2
//                             encoding over [-12.47393, 4.026069] EV, the base
//                             contrast sigmoid as the 6th-order polynomial fit of
//                             Benjamin Wrensch's "minimal AgX", LOOK = 1 the
//                             punchy look (ASC CDL power 1.35, saturation 1.4),
//                             outset (inverse inset) matrix, then the 2.2 power
//                             back to linear display light
//   out = clamp(y, 0, 1); alpha is kept.
#define OPERATOR 1
#define LOOK 0

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    exposure: f32, // @default(0) @range(-20, 20) exposure in stops applied before the curve
    white: f32,    // @default(0) @range(0, 65000) Reinhard extended: the value mapped to 1 (0: plain Reinhard)
}
@group(0) @binding(1) var<uniform> params: Params;

// Khronos PBR Neutral (https://github.com/KhronosGroup/ToneMapping, PBR_Neutral):
// start compression 0.8 - 0.04, desaturation 0.15.
fn pbr_neutral(c_in: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    var c = c_in;
    let x = min(c.r, min(c.g, c.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    c -= offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3<f32>(new_peak), g);
}

// AgX base contrast: the sigmoid on the log-encoded [0, 1] value, as a
// polynomial (mean error 1.85e-4 against Blender's LUT, per its author).
fn agx_contrast(x: vec3<f32>) -> vec3<f32> {
    let x2 = x * x;
    let x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
}

fn agx(c: vec3<f32>) -> vec3<f32> {
    // inset (columns: the images of red, green and blue)
    let inset = mat3x3<f32>(
        vec3<f32>(0.842479062253094, 0.0423282422610123, 0.0423756549057051),
        vec3<f32>(0.0784335999999992, 0.878468636469772, 0.0784336),
        vec3<f32>(0.0792237451477643, 0.0791661274605434, 0.879142973793104),
    );
    let outset = mat3x3<f32>(
        vec3<f32>(1.19687900512017, -0.0528968517574562, -0.0529716355144438),
        vec3<f32>(-0.0980208811401368, 1.15190312990417, -0.0980434501171241),
        vec3<f32>(-0.0990297440797205, -0.0989611768448433, 1.15107367264116),
    );
    let min_ev = -12.47393;
    let max_ev = 4.026069;
    var v = inset * c;
    v = clamp(log2(max(v, vec3<f32>(1e-10))), vec3<f32>(min_ev), vec3<f32>(max_ev));
    v = (v - min_ev) / (max_ev - min_ev);
    v = agx_contrast(v);
#if LOOK == 1
    // punchy: slope 1, offset 0, power 1.35, saturation 1.4 about the Rec.709
    // luma of the value before the power
    let luma = dot(v, vec3<f32>(0.2126, 0.7152, 0.0722));
    v = pow(max(v, vec3<f32>(0.0)), vec3<f32>(1.35));
    v = luma + 1.4 * (v - luma);
#endif
    v = outset * v;
    return pow(max(v, vec3<f32>(0.0)), vec3<f32>(2.2));
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let x = max(c.rgb, vec3<f32>(0.0)) * exp2(params.exposure);
#if OPERATOR == 0
    var y = x / (1.0 + x);
    if (params.white > 0.0) {
        y *= 1.0 + x / (params.white * params.white);
    }
#elif OPERATOR == 1
    let y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
#elif OPERATOR == 2
    let y = pbr_neutral(x);
#else
    let y = agx(x);
#endif
    return vec4<f32>(clamp(y, vec3<f32>(0.0), vec3<f32>(1.0)), c.a);
}
