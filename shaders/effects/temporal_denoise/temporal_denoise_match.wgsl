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
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` gives each
// output texel LANES invocations (32 at the coarsest level, 8 at the others;
// 256 a workgroup) that stage its block in workgroup memory once and evaluate
// the candidates of a step side by side (the 26 of the exhaustive search, the 6
// predictors, the 8 neighbours of a refinement round, the 5 costs of the
// parabola), each cost summed by one lane in fs_main's order; lane 0 then
// scans them in fs_main's order. `fs_main` evaluates them one after another
// where the output cannot be a storage texture. The same vectors: measured
// difference 0 (tests/compute_native.rs). Lanes share a texel, so fragment
// execution (`auto` on lavapipe) draws `fs_main`.
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
@group(0) @binding(6) var out: texture_storage_2d<rg32float, write>;

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

// cs_main: TEXELS output texels of LANES lanes each. Workgroup memory: the
// texels' blocks (at most 6 x 6 each), a candidate (vector, cost) per lane,
// and each texel's best vector and cost so far.
#if COARSEST == 1
const LANES: i32 = 32;
const TEXELS_X: i32 = 4;
#else
const LANES: i32 = 8;
const TEXELS_X: i32 = 8;
#endif
var<workgroup> cs_block: array<f32, 1152>;
var<workgroup> cs_vec: array<vec2<f32>, 256>;
var<workgroup> cs_cost: array<f32, 256>;
var<workgroup> cs_best: array<vec2<f32>, 32>;
var<workgroup> cs_best_cost: array<f32, 32>;

// The cost of vector `v` for the block of texel `t` (at `org`): fs_main's cost.
fn cs_block_cost(t: i32, org: vec2<i32>, v: vec2<f32>) -> f32 {
    var s = 0.0;
    for (var j = 0; j < WINDOW; j++) {
        for (var i = 0; i < WINDOW; i++) {
            let uv = (vec2<f32>(org + vec2<i32>(i, j)) + 0.5) * params.cur_texel + v;
            let d = cs_block[(t * WINDOW + j) * WINDOW + i] - textureSampleLevel(prev, prev_sampler, uv, 0.0).r;
            s += d * d;
        }
    }
    return s / f32(WINDOW * WINDOW);
}

// Lane `lane`'s candidate of texel `t`: its vector and cost.
fn cs_candidate(t: i32, lane: i32, org: vec2<i32>, v: vec2<f32>) {
    cs_vec[t * LANES + lane] = v;
    cs_cost[t * LANES + lane] = cs_block_cost(t, org, v);
}

// After a barrier, lane 0 scans the first `n` candidates of texel `t` in
// fs_main's order from its best so far, keeping the first strictly lower cost;
// every lane may read the result after the closing barrier.
fn cs_scan(t: i32, lane: i32, n: i32) {
    workgroupBarrier();
    if (lane == 0) {
        var b = cs_best[t];
        var bc = cs_best_cost[t];
        for (var k = 0; k < n; k++) {
            let c = cs_cost[t * LANES + k];
            if (c < bc) {
                b = cs_vec[t * LANES + k];
                bc = c;
            }
        }
        cs_best[t] = b;
        cs_best_cost[t] = bc;
    }
    workgroupBarrier();
}

// Candidate `k` of the first step after zero: the temporal predictor, then the
// exhaustive offsets in fs_main's order without (0, 0) (COARSEST) or the coarse
// level's four vectors nearest to the block (`g`).
fn cs_first_step(k: i32, last_v: vec2<f32>, g: vec2<i32>) -> vec2<f32> {
    if (k == 0) {
        return last_v;
    }
#if COARSEST == 1
    let side = 2 * RADIUS + 1;
    let m = select(k - 1, k, k - 1 >= side * side / 2);
    return vec2<f32>(f32(m % side - RADIUS), f32(m / side - RADIUS)) * params.cur_texel;
#else
    let m = k - 1;
    return tdn_load(coarse, g + vec2<i32>(m & 1, m >> 1)).xy;
#endif
}

#if COARSEST == 1
@compute @workgroup_size(4, 2, 32)
#else
@compute @workgroup_size(8, 4, 8)
#endif
fn cs_main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let o = vec2<i32>(id.xy);
    let q = min(o, vec2<i32>(params.out_size) - vec2<i32>(1));
    let lane = i32(local.z);
    let t = i32(local.y) * TEXELS_X + i32(local.x);
    let uvc = (vec2<f32>(q) + 0.5) / params.out_size;
    let org = vec2<i32>(floor(uvc * params.cur_size - 0.5 * f32(WINDOW) + 0.5));
    for (var i = lane; i < WINDOW * WINDOW; i += LANES) {
        cs_block[t * WINDOW * WINDOW + i] = tdn_load(cur, org + vec2<i32>(i % WINDOW, i / WINDOW)).r;
    }
    workgroupBarrier();
    let tx = params.cur_texel;
    var last_v = tdn_load(last, q).xy;
    if (params.frame == 0u) {
        last_v = vec2<f32>(0.0);
    }
#if COARSEST == 1
    let n = (2 * RADIUS + 1) * (2 * RADIUS + 1);
    let g = vec2<i32>(0);
#else
    let n = 5;
    let g = vec2<i32>(floor(uvc * vec2<f32>(textureDimensions(coarse)) - 0.5));
#endif
    // Step 1: zero, preferred on near-ties (on the last lane, which has no
    // candidate in the first round when there are fewer than LANES), then the
    // others LANES at a time.
    if (lane == LANES - 1) {
        cs_best[t] = vec2<f32>(0.0);
        cs_best_cost[t] = 0.97 * cs_block_cost(t, org, vec2<f32>(0.0));
    }
    for (var first = 0; first < n; first += LANES) {
        if (first + lane < n) {
            cs_candidate(t, lane, org, cs_first_step(first + lane, last_v, g));
        }
        cs_scan(t, lane, min(LANES, n - first));
    }
#if COARSEST == 0
    // Up to two rounds of the 8 neighbours one texel away; a texel whose best
    // stayed put is done (fs_main's break): its lanes idle through the second.
    var settled = false;
    for (var round = 0; round < 2; round++) {
        let centre = cs_best[t];
        let k = select(lane, lane + 1, lane >= 4);
        if (!settled) {
            cs_candidate(t, lane, org, centre + vec2<f32>(f32(k % 3 - 1), f32(k / 3 - 1)) * tx);
        }
        cs_scan(t, lane, select(8, 0, settled));
        settled = settled || all(cs_best[t] == centre);
    }
#endif
    // The parabola through the costs one texel left, right, up and down.
    let b = cs_best[t];
    let offsets = array<vec2<f32>, 5>(
        vec2<f32>(-tx.x, 0.0),
        vec2<f32>(tx.x, 0.0),
        vec2<f32>(0.0, -tx.y),
        vec2<f32>(0.0, tx.y),
        vec2<f32>(0.0),
    );
    if (lane < 5) {
        cs_candidate(t, lane, org, b + offsets[lane]);
    }
    workgroupBarrier();
    if (lane != 0 || any(o != q)) {
        return;
    }
    let c = t * LANES;
    let sub = vec2<f32>(
        tdn_parabola(cs_cost[c], cs_cost[c + 4], cs_cost[c + 1]),
        tdn_parabola(cs_cost[c + 2], cs_cost[c + 4], cs_cost[c + 3]),
    );
    textureStore(out, o, vec4<f32>(b + sub * tx, 0.0, 0.0));
}
