// A shader for the binding tests: one texture, one parameter with a range.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

struct Params {
    gain: f32,      // @default(1) @range(0, 4) multiplies the colour
    offset: vec3<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main(@location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let c = textureSampleLevel(img, img_sampler, uv, 0.0);
    return vec4<f32>(c.rgb * params.gain + params.offset, c.a);
}
