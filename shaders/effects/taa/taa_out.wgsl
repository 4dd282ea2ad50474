// taa_out: the output of the `taa` effect (effects/taa.fx): the resolved colour of
// the state, the mean of the HISTORY_SCALE x HISTORY_SCALE state texels that
// cover the pixel (a box filter over the pixel's area), with the current frame's
// alpha. VIEW 1 shows the history length instead: n / frames as grey (1: a full
// history, 1 / frames: none), n = 1 + the weight the history brought (the
// state's weight less this frame's own samples, taa_resolve.wgsl) over the
// weight of one frame, the largest of the pixel's texels (without jitter only
// the texel at the sample collects a full weight; a reset clears them all).
@group(0) @binding(0) var state: texture_2d<f32>;
@group(0) @binding(1) var cur: texture_2d<f32>;

struct Params {
    frames: f32,       // @default(10) @range(1, 64) most frames the history stands for (for VIEW 1)
    filter_width: f32, // @default(0.13) @range(0.05, 2) the resolve's sample Gaussian, sigma in input pixels (for VIEW 1)
    jitter: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#define VIEW 0
const HISTORY_SCALE: i32 = 3;

#if VIEW == 1
// The weight this frame's samples gave the state texel centred at x (input
// pixels), as taa_resolve.wgsl computes it, plus its small fallback weight.
fn own_weight(x: vec2<f32>, p: vec2<i32>) -> f32 {
    let inv2s2 = 0.5 / (params.filter_width * params.filter_width);
    var w = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let d = vec2<f32>(p + vec2<i32>(dx, dy)) + 0.5 + params.jitter - x;
            w += exp(-dot(d, d) * inv2s2);
        }
    }
    return w + 0.01 * 6.2831853 * params.filter_width * params.filter_width;
}

// n of pixel p: 1 + the history's weight over one frame's, the largest of its texels.
fn history_frames(p: vec2<i32>) -> f32 {
    let per_frame = 6.2831853 * params.filter_width * params.filter_width;
    var n = 0.0;
    for (var j = 0; j < HISTORY_SCALE; j++) {
        for (var i = 0; i < HISTORY_SCALE; i++) {
            let t = HISTORY_SCALE * p + vec2<i32>(i, j);
            let x = (vec2<f32>(t) + 0.5) / f32(HISTORY_SCALE);
            let w = textureLoad(state, t, 0).a - own_weight(x, p);
            n = max(n, 1.0 + max(w, 0.0) / per_frame);
        }
    }
    return n;
}
#endif

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    var s = vec4<f32>(0.0);
    for (var j = 0; j < HISTORY_SCALE; j++) {
        for (var i = 0; i < HISTORY_SCALE; i++) {
            s += textureLoad(state, HISTORY_SCALE * p + vec2<i32>(i, j), 0);
        }
    }
    s /= f32(HISTORY_SCALE * HISTORY_SCALE);
#if VIEW == 1
    let v = history_frames(p) / params.frames;
    return vec4<f32>(v, v, v, 1.0);
#else
    return vec4<f32>(s.rgb, textureLoad(cur, p, 0).a);
#endif
}
