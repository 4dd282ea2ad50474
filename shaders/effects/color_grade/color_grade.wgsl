// colorGrade: ASC CDL (slope, offset, power, saturation) followed by lift/gamma/gain,
// per pixel, on the values as they come (linear light unless the pass says otherwise):
//
//   1. CDL SOP:  v = in * slope + offset;  clamp_range: v = clamp(v, 0, 1)
//                v = v^power  (v > 0; without clamp_range values <= 0 pass unchanged)
//   2. CDL saturation (Rec. 709 luma, as in the ASC CDL v1.2 spec):
//                luma = 0.2126 r + 0.7152 g + 0.0722 b;  v = luma + saturation * (v - luma)
//                clamp_range: v = clamp(v, 0, 1)
//   3. Lift/gamma/gain:  v = gain * (v + lift * (1 - v));  v = v^(1 / gamma)  (v > 0)
//
// Alpha is kept. Identity: slope 1, offset 0, power 1, saturation 1, lift 0,
// gamma 1, gain 1 (and, with clamp_range, inputs in [0, 1]).
@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    slope: vec3<f32>,  // @default(1, 1, 1) @range(0, 100) ASC CDL slope (multiplier)
    offset: vec3<f32>, // @default(0, 0, 0) @range(-10, 10) ASC CDL offset (added after the slope)
    power: vec3<f32>,  // @default(1, 1, 1) @range(0.01, 100) ASC CDL power (exponent)
    saturation: f32,   // @default(1) @range(0, 10) ASC CDL saturation (0: grey, 1: unchanged)
    lift: vec3<f32>,   // @default(0, 0, 0) @range(-1, 1) raises (or lowers) the blacks, leaves 1 fixed
    gamma: vec3<f32>,  // @default(1, 1, 1) @range(0.01, 100) midtones: v^(1 / gamma); > 1 brightens
    gain: vec3<f32>,   // @default(1, 1, 1) @range(0, 100) multiplier of the whole range
    clamp_range: f32,  // @default(1) @range(0, 1) 1: clamp to [0, 1] after SOP and saturation (ASC); 0: no clamp
}
@group(0) @binding(1) var<uniform> params: Params;

// v^e for v > 0; other values, and exponents of exactly 1, leave v unchanged (so
// that the identity grade is exact).
fn safe_pow(v: vec3<f32>, e: vec3<f32>) -> vec3<f32> {
    return select(v, pow(max(v, vec3<f32>(1e-30)), e), v > vec3<f32>(0.0) & e != vec3<f32>(1.0));
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let clamping = params.clamp_range > 0.5;
    var v = c.rgb * params.slope + params.offset;
    if (clamping) {
        v = clamp(v, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    v = safe_pow(v, params.power);
    let luma = dot(v, vec3<f32>(0.2126, 0.7152, 0.0722));
    v = luma + params.saturation * (v - luma);
    if (clamping) {
        v = clamp(v, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    v = params.gain * (v + params.lift * (1.0 - v));
    v = safe_pow(v, 1.0 / params.gamma);
    return vec4<f32>(v, c.a);
}
