// tdn_match: one level of temporal_denoise's hierarchical block matching
// (effects/temporal_denoise.fx). Output: one motion vector per texel, in uv units,
// pointing from this frame to the previous one: cur(uv) ~ prev(uv + v).
//
// The block of a vector is the WINDOW x WINDOW texels of the luma level `cur`
// centred on the output texel's centre; its cost for a vector v is the mean
// squared difference to `prev` sampled (bilinearly) at the same texels moved by v.
//   COARSEST = 1  exhaustive search over the integer offsets in [-RADIUS, RADIUS]^2
//                 texels, plus this pass's own vector of the previous frame (`last`,
//                 the temporal predictor).
//   COARSEST = 0  the candidates are the four vectors of the coarser level
//                 (`coarse`) nearest to the block, the temporal predictor and zero;
//                 the best one is refined by steps of one texel (up to two rounds
//                 of the 8 neighbours).
// Finally a parabola through the costs of the best vector and its neighbours
// (one texel left/right, up/down) gives the sub-texel offset.
// Zero (no motion) is preferred on near-ties: its cost is scaled by 0.97.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var prev: texture_2d<f32>;
@group(0) @binding(2) var prev_sampler: sampler;
@group(0) @binding(3) var last: texture_2d<f32>;
#define COARSEST 0
#if COARSEST == 0
@group(0) @binding(4) var coarse: texture_2d<f32>;
#endif

struct Params {
    out_size: vec2<f32>,
    cur_size: vec2<f32>,
    cur_texel: vec2<f32>,
    frame: u32,
}
@group(0) @binding(5) var<uniform> params: Params;

#define WINDOW 4
#define RADIUS 3

#include "lib/temporal_denoise.wgsl"

var<private> block: array<f32, 64>;
var<private> origin: vec2<i32>;

fn cost(v: vec2<f32>) -> f32 {
    var s = 0.0;
    for (var j = 0; j < WINDOW; j++) {
        for (var i = 0; i < WINDOW; i++) {
            let t = origin + vec2<i32>(i, j);
            let uv = (vec2<f32>(t) + 0.5) * params.cur_texel + v;
            let d = block[j * WINDOW + i] - textureSampleLevel(prev, prev_sampler, uv, 0.0).r;
            s += d * d;
        }
    }
    return s / f32(WINDOW * WINDOW);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let q = vec2<i32>(pos.xy);
    let uvc = pos.xy / params.out_size;
    origin = vec2<i32>(floor(uvc * params.cur_size - 0.5 * f32(WINDOW) + 0.5));
    for (var j = 0; j < WINDOW; j++) {
        for (var i = 0; i < WINDOW; i++) {
            block[j * WINDOW + i] = tdn_load(cur, origin + vec2<i32>(i, j)).r;
        }
    }
    let tx = params.cur_texel;
    var best = vec2<f32>(0.0);
    var best_cost = 0.97 * cost(best);
    var v = tdn_load(last, q).xy;
    if (params.frame == 0u) {
        v = vec2<f32>(0.0);
    }
    var c = cost(v);
    if (c < best_cost) {
        best = v;
        best_cost = c;
    }
#if COARSEST == 1
    for (var dy = -RADIUS; dy <= RADIUS; dy++) {
        for (var dx = -RADIUS; dx <= RADIUS; dx++) {
            if (dx == 0 && dy == 0) {
                continue;
            }
            v = vec2<f32>(f32(dx), f32(dy)) * tx;
            c = cost(v);
            if (c < best_cost) {
                best = v;
                best_cost = c;
            }
        }
    }
#else
    let g = vec2<i32>(floor(uvc * vec2<f32>(textureDimensions(coarse)) - 0.5));
    for (var k = 0; k < 4; k++) {
        v = tdn_load(coarse, g + vec2<i32>(k & 1, k >> 1)).xy;
        c = cost(v);
        if (c < best_cost) {
            best = v;
            best_cost = c;
        }
    }
    for (var round = 0; round < 2; round++) {
        let centre = best;
        for (var k = 0; k < 9; k++) {
            let o = vec2<f32>(f32(k % 3 - 1), f32(k / 3 - 1));
            if (k == 4) {
                continue;
            }
            v = centre + o * tx;
            c = cost(v);
            if (c < best_cost) {
                best = v;
                best_cost = c;
            }
        }
        if (all(best == centre)) {
            break;
        }
    }
#endif
    let cl = cost(best - vec2<f32>(tx.x, 0.0));
    let cr = cost(best + vec2<f32>(tx.x, 0.0));
    let cu = cost(best - vec2<f32>(0.0, tx.y));
    let cd = cost(best + vec2<f32>(0.0, tx.y));
    let c0 = cost(best);
    let sub = vec2<f32>(tdn_parabola(cl, c0, cr), tdn_parabola(cu, c0, cd));
    return vec4<f32>(best + sub * tx, 0.0, 0.0);
}
