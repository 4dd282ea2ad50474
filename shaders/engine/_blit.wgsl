// Built-in: copies `img` to the output target (which may have another format).
@group(0) @binding(0) var img: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(img, vec2<i32>(pos.xy), 0);
}
