// A type error: vec3 + vec4 (the diagnostic must name WGSL types, not naga's).
@group(0) @binding(0) var img: texture_2d<f32>;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let v: vec3<f32> = c.rgb;
    let w = v + c;
    return vec4<f32>(w, 1.0);
}
