// Built-in: converts `img` between linear light and sRGB encoding (exact sRGB curve).
// TO_LINEAR = 1: sRGB-encoded -> linear; 0: linear -> sRGB-encoded. Alpha is kept.
@group(0) @binding(0) var img: texture_2d<f32>;

fn to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

fn to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = max(c, vec3<f32>(0.0));
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
#if TO_LINEAR
    return vec4<f32>(to_linear(c.rgb), c.a);
#else
    return vec4<f32>(to_srgb(c.rgb), c.a);
#endif
}
