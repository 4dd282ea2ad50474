// tests/mipmap.rs: level LEVEL of `img` read with textureLoad, its edge texels
// repeated past its size.
@group(0) @binding(0) var img: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(img, LEVEL));
    return textureLoad(img, min(vec2<i32>(pos.xy), size - 1), LEVEL);
}
