// add: img1 + intensity * img2 (img2 is resampled bilinearly to img1's size).
@group(0) @binding(0) var img1: texture_2d<f32>;
@group(0) @binding(1) var img2: texture_2d<f32>;
@group(0) @binding(2) var img2_sampler: sampler;

struct Params {
    intensity: f32, // @default(1) @range(0, 100) strength of the added image
}
@group(0) @binding(3) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv: vec2<f32>) -> @location(0) vec4<f32> {
    let a = textureLoad(img1, vec2<i32>(pos.xy), 0);
    let b = textureSampleLevel(img2, img2_sampler, uv, 0.0);
    return vec4<f32>(a.rgb + params.intensity * b.rgb, a.a);
}
