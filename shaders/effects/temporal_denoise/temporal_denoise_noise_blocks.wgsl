// tdn_noise_blk: second step of temporal_denoise's noise estimate
// (effects/temporal_denoise.fx): the mean of 4x4 texels of tdn_noise_res (a block
// of 16x16 input pixels) in r, and in g whether any of them is clipped (max).
@group(0) @binding(0) var img: texture_2d<f32>;

#include "lib/temporal_denoise.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = vec2<i32>(pos.xy) * 4;
    var total = 0.0;
    var clipped = 0.0;
    for (var j = 0; j < 4; j++) {
        for (var i = 0; i < 4; i++) {
            let t = tdn_load(img, base + vec2<i32>(i, j));
            total += t.r;
            clipped = max(clipped, t.g);
        }
    }
    return vec4<f32>(total / 16.0, clipped, 0.0, 1.0);
}
