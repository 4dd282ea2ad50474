// tdn_out: temporal_denoise's output (effects/temporal_denoise.fx): the temporal
// average `acc` (rgb; a = the frames n it averages), blended with a spatial
// estimate where n is small (the fallback where the motion search failed:
// occlusions, new content at the frame edge, scene cuts, the first frame):
//   s   = bilateral 5x5 of cur: weights exp(-|x|^2 / 4.5) * exp(-|dc|^2 / (2 (1.5 sigma)^2)),
//         |dc|^2 the mean over r, g, b of the squared difference to the centre
//   out = mix(acc.rgb, s, spatial / n), alpha = cur's alpha
// VIEW (debugging, tests): 0 the denoised image, 1 the noise level sigma (grey),
// 2 n / frames (grey), 3 the motion vector (r, g = 0.5 + v in pixels / 8).
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var acc: texture_2d<f32>;
@group(0) @binding(2) var sig: texture_2d<f32>;
@group(0) @binding(3) var mv: texture_2d<f32>;

struct Params {
    spatial: f32, // @default(1) @range(0, 1) weight of the spatial fallback where the history is short
    frames: f32,  // @default(12) @range(1, 64) most frames the running mean averages
    out_size: vec2<f32>,
}
@group(0) @binding(4) var<uniform> params: Params;

#define VIEW 0

#include "lib/temporal_denoise.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(cur, p, 0);
    let a = textureLoad(acc, p, 0);
    let sigma = max(textureLoad(sig, vec2<i32>(0), 0).r, 1e-4);
#if VIEW == 1
    return vec4<f32>(vec3<f32>(sigma), 1.0);
#elif VIEW == 2
    return vec4<f32>(vec3<f32>(a.a / params.frames), 1.0);
#elif VIEW == 3
    let v = tdn_field(mv, pos.xy / params.out_size) * params.out_size;
    return vec4<f32>(0.5 + v / 8.0, 0.5, 1.0);
#else
    let ws = params.spatial / max(a.a, 1.0);
    if (ws < 0.01) {
        return vec4<f32>(a.rgb, c.a);
    }
    let kr = -0.5 / (2.25 * sigma * sigma);
    var sum = vec3<f32>(0.0);
    var total = 0.0;
    for (var j = -2; j <= 2; j++) {
        for (var i = -2; i <= 2; i++) {
            let t = tdn_load(cur, p + vec2<i32>(i, j)).rgb;
            let d = t - c.rgb;
            let w = exp(-f32(i * i + j * j) / 4.5 + kr * dot(d, d) / 3.0);
            sum += w * t;
            total += w;
        }
    }
    return vec4<f32>(mix(a.rgb, sum / total, ws), c.a);
#endif
}
