// tests/mipmap.rs: the top row holds the LUT's size (in codes), the rest the
// LUT sampled over the whole output.
@group(0) @binding(0) var lut: texture_2d<f32>;
@group(0) @binding(1) var lut_sampler: sampler;

struct Params {
    lut_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main(@location(0) uv: vec2<f32>, @builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    if pos.y < 1.0 {
        return vec4<f32>(params.lut_size / 255.0, 0.0, 1.0);
    }
    return textureSampleLevel(lut, lut_sampler, uv, 0.0);
}
