// tests/mipmap.rs: textureSample picks the level from the screen-space
// derivatives, which only the fragment stage has.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    return textureSample(img, img_sampler, uv);
}
