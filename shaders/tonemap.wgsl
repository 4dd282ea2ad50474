// tonemap: maps linear HDR colour to display-referred linear [0, 1], per channel:
//   x = max(in, 0) * 2^exposure
//   OPERATOR = 0 (Reinhard):  white <= 0: y = x / (1 + x)
//                             white  > 0: y = x (1 + x / white^2) / (1 + x)   (extended: white -> 1)
//   OPERATOR = 1 (ACES, Narkowicz 2015 filmic fit):
//                             y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//   out = clamp(y, 0, 1); alpha is kept.
#define OPERATOR 1

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    exposure: f32, // @default(0) @range(-20, 20) exposure in stops applied before the curve
    white: f32,    // @default(0) @range(0, 65000) Reinhard extended: the value mapped to 1 (0: plain Reinhard)
}
@group(0) @binding(1) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let x = max(c.rgb, vec3<f32>(0.0)) * exp2(params.exposure);
#if OPERATOR == 0
    var y = x / (1.0 + x);
    if (params.white > 0.0) {
        y *= 1.0 + x / (params.white * params.white);
    }
#else
    let y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
#endif
    return vec4<f32>(clamp(y, vec3<f32>(0.0), vec3<f32>(1.0)), c.a);
}
