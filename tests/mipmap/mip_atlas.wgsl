// tests/mipmap.rs: a 64 x 64 output of a 64 x 64 mipmapped input.
// Rows 0..32: level L (1 to 6, 64 >> L texels a side) read with textureLoad at
// x from 64 - (128 >> L); black elsewhere.
// Rows 32..64: textureSampleLevel at level 2.0 (nearest filtering), at
// uv = ((x + 0.5) / 64, (y - 32 + 0.5) / 32).
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    if p.y >= 32 {
        let uv = vec2<f32>(pos.x / 64.0, (pos.y - 32.0) / 32.0);
        return textureSampleLevel(img, img_sampler, uv, 2.0);
    }
    for (var level = 1; level <= 6; level++) {
        let side = 64 >> u32(level);
        let x0 = 64 - (128 >> u32(level));
        if p.x >= x0 && p.x < x0 + side && p.y < side {
            return textureLoad(img, vec2<i32>(p.x - x0, p.y), level);
        }
    }
    return vec4<f32>(0.0, 0.0, 0.0, 1.0);
}
