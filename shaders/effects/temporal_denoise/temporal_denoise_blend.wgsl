// tdn_blend: temporal_denoise's recursive, motion-compensated average
// (effects/temporal_denoise.fx). Per pixel, with cur = this frame, w = the warped
// state (tdn_warp: rgb = the previous temporal average moved onto this frame,
// a = the number of frames it averages, n_prev) and sigma = the noise level:
//   D   = cur - w.rgb                                      per channel
//   r1  = mean over r, g, b of |mean of D over 3x3| / sigma  (a local offset)
//   r2  = sqrt(mean of D^2 over 3x3 and r, g, b) / sigma      (any local mismatch)
//   k   = (1 - smoothstep(0.5, 1.0, r1 / threshold))
//       * (1 - smoothstep(1.2, 1.8, r2 / threshold))         trust in the history
//   For a correct match D is noise: r1 is about 0.3, r2 about sqrt(1 + 1/n_prev).
//   n   = 1 + k * min(n_prev, frames - 1)
//   out = rgb: cur + (1 - 1/n') (w.rgb - cur) with n' = n, i.e. the running mean of
//         n frames; a: n
// Where the motion compensation fails (occlusion, new content, a cut, a wrong
// vector), m is large, k = 0, n = 1: the state restarts from the current frame.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var warped: texture_2d<f32>;
@group(0) @binding(2) var sig: texture_2d<f32>;

struct Params {
    frames: f32,    // @default(12) @range(1, 64) most frames the running mean averages
    threshold: f32, // @default(1) @range(0.1, 10) motion-rejection threshold, in units of sigma
}
@group(0) @binding(3) var<uniform> params: Params;

#include "lib/temporal_denoise.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(cur, p, 0);
    let w = textureLoad(warped, p, 0);
    let sigma = max(textureLoad(sig, vec2<i32>(0), 0).r, 1e-4);
    var box = vec3<f32>(0.0);
    var sq = 0.0;
    for (var j = -1; j <= 1; j++) {
        for (var i = -1; i <= 1; i++) {
            let q = p + vec2<i32>(i, j);
            let d = tdn_load(cur, q).rgb - tdn_load(warped, q).rgb;
            box += d;
            sq += dot(d, d);
        }
    }
    let ts = params.threshold * sigma;
    let r1 = dot(abs(box / 9.0), vec3<f32>(1.0 / 3.0)) / ts;
    let r2 = sqrt(sq / 27.0) / ts;
    let k = (1.0 - smoothstep(0.5, 1.0, r1)) * (1.0 - smoothstep(1.2, 1.8, r2));
    let n = 1.0 + k * min(w.a, params.frames - 1.0);
    return vec4<f32>(mix(c.rgb, w.rgb, 1.0 - 1.0 / n), n);
}
