// tdn_noise_res: first step of temporal_denoise's noise estimate
// (effects/temporal_denoise.fx). Each output texel covers 4x4 input pixels (the
// pass is a quarter of the input's size) and holds
//   r = the mean over those pixels and over r, g, b of |N * I|, N the 3x3
//       Laplacian-difference kernel (1 -2 1; -2 4 -2; 1 -2 1), which cancels
//       constant, linear and (separately) quadratic content; for white Gaussian
//       noise of standard deviation sigma, E|N * I| = 6 sigma sqrt(2 / pi)
//   g = 1 if any of the pixels is near black or white (within 2/255: clipped noise
//       would read low), else 0
// Pixels on the image border use the nearest interior pixel.
@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    img_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;

#include "lib/temporal_denoise.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let s = vec2<i32>(params.img_size);
    let base = vec2<i32>(pos.xy) * 4;
    var total = 0.0;
    var clipped = 0.0;
    for (var j = 0; j < 4; j++) {
        for (var i = 0; i < 4; i++) {
            let p = clamp(base + vec2<i32>(i, j), vec2<i32>(1), max(s - 2, vec2<i32>(1)));
            var r = vec3<f32>(0.0);
            for (var dy = -1; dy <= 1; dy++) {
                for (var dx = -1; dx <= 1; dx++) {
                    let w = select(-2.0, 1.0, dx != 0) * select(-2.0, 1.0, dy != 0);
                    r += w * tdn_load(img, p + vec2<i32>(dx, dy)).rgb;
                }
            }
            total += dot(abs(r), vec3<f32>(1.0 / 3.0));
            let c = tdn_load(img, p).rgb;
            if (any(c < vec3<f32>(2.0 / 255.0)) || any(c > vec3<f32>(253.0 / 255.0))) {
                clipped = 1.0;
            }
        }
    }
    return vec4<f32>(total / 16.0, clipped, 0.0, 1.0);
}
