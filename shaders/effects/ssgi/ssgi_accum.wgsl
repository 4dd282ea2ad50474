// ssgi_accum: temporal accumulation of the raw indirect light of the `ssgi` effect
// (effects/ssgi.fx has the method in words).
//
// Inputs: `cur` this frame's raw estimate (shaders/effects/ssgi/ssgi_trace.wgsl: rgb = E / pi,
// a = linear depth, 0 without geometry), `cur_prev` the same one frame earlier
// (its a: the depth the history was made at), `hist` this pass's own output one
// frame earlier (rgb = the running mean, a = n, the frames it stands for; zero
// before the first frame), `motion` (AUX.motion, pixels, current minus previous
// position: the pixel p was at p - motion).
//
// Per pixel p with geometry (the others get 0):
//   prev = p - motion(p); the history is kept when prev lies inside the frame and
//   the depth stored there one frame earlier (nearest texel) is within
//   depth_tolerance * d of the current depth d (else: a disocclusion, n_prev = 0);
//   it is read bilinearly at prev, clamped to the box mean +- clip_gamma sigma
//   of the 3x3 current estimates (stale light after a change cannot survive), and
//       n = min(n_prev, frames - 1) + 1,   out.rgb = hist + (cur - hist) / n
//   so the state is the mean of the last n frames' estimates (each frame's noise
//   pattern differs: the golden-ratio shift of ssgi_trace.wgsl), up to `frames`.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var cur_prev: texture_2d<f32>;
@group(0) @binding(2) var hist: texture_2d<f32>;
@group(0) @binding(3) var hist_sampler: sampler;
@group(0) @binding(4) var motion: texture_2d<f32>;

struct Params {
    frames: f32,          // @default(8) @range(1, 64) most frames the history stands for (1: no temporal filter)
    depth_tolerance: f32, // @default(0.1) @range(0, 10) relative depth change beyond which the reprojected history is a disocclusion
    clip_gamma: f32,      // @default(2) @range(0.25, 100) half-width of the history clipping box, in standard deviations of the 3x3 current estimates
    out_size: vec2<f32>,
}
@group(0) @binding(5) var<uniform> params: Params;

#include "lib/view.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(cur, p, 0);
    let d = c.a;
    if (!lib_has_geometry(d)) {
        return vec4<f32>(0.0);
    }
    // Moments of the 3x3 current estimates (pixels with geometry).
    let size = vec2<i32>(params.out_size);
    var m1 = vec3<f32>(0.0);
    var m2 = vec3<f32>(0.0);
    var count = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2<i32>(dx, dy);
            if (!lib_inside(q, size)) {
                continue;
            }
            let e = textureLoad(cur, q, 0);
            if (!lib_has_geometry(e.a)) {
                continue;
            }
            m1 += e.rgb;
            m2 += e.rgb * e.rgb;
            count += 1.0;
        }
    }
    let mean = m1 / count;
    let sigma = sqrt(max(m2 / count - mean * mean, vec3<f32>(0.0)));
    let lo = mean - params.clip_gamma * sigma;
    let hi = mean + params.clip_gamma * sigma;
    // Where p was one frame earlier, and whether the history there is this surface.
    let prev = pos.xy - textureLoad(motion, p, 0).xy;
    var n_prev = 0.0;
    var h = vec3<f32>(0.0);
    if (all(prev >= vec2<f32>(0.0)) && all(prev < params.out_size)) {
        let d_prev = textureLoad(cur_prev, vec2<i32>(prev), 0).a;
        if (abs(d_prev - d) <= params.depth_tolerance * d) {
            let s = textureSampleLevel(hist, hist_sampler, prev / params.out_size, 0.0);
            n_prev = min(s.a, params.frames - 1.0);
            h = clamp(s.rgb, lo, hi);
        }
    }
    let n = n_prev + 1.0;
    let e = h + (c.rgb - h) / n;
    let finite = select(vec3<f32>(0.0), e, e == e);
    return vec4<f32>(clamp(finite, vec3<f32>(0.0), vec3<f32>(65504.0)), n);
}
