// tdn_refine: the last, sub-pixel level of temporal_denoise's motion search
// (effects/temporal_denoise.fx). Same output as tdn_match (one uv-unit vector per
// texel, cur(uv) ~ hist(uv + v)), but the block is WINDOW x WINDOW pixels of the
// full-resolution luma of this frame (`cur`), matched against the filter's own
// previous output (`hist`, the denoised state, sampled bilinearly): far less
// noise than the previous input.
// Candidates: the vectors of the coarser level (`coarse`) at the block and its
// four neighbours; the best is refined by 1/4-pixel steps (its 8 neighbours),
// and where it stays best a parabola through the costs of its neighbours along x
// and along y gives the final sub-pixel offset.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main` gives each
// output texel 8 lanes (32 texels a workgroup) that stage its 8 x 8 block of
// `cur` luma in workgroup memory once and evaluate a step's candidates side by
// side (the 5 coarse vectors, then the 8 quarter-pixel steps), each cost summed
// by one lane in fs_main's order; lane 0 scans them in fs_main's order.
// `fs_main` evaluates them one after another where the output cannot be a
// storage texture. The same vectors: measured difference 0
// (tests/compute_native.rs). Lanes share a texel, so fragment execution (`auto`
// on lavapipe) draws `fs_main`.
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var hist: texture_2d<f32>;
@group(0) @binding(2) var hist_sampler: sampler;
@group(0) @binding(3) var coarse: texture_2d<f32>;

struct Params {
    out_size: vec2<f32>,
    cur_size: vec2<f32>,
    cur_texel: vec2<f32>,
}
@group(0) @binding(4) var<uniform> params: Params;
@group(0) @binding(5) var out: texture_storage_2d<rg32float, write>;

#define WINDOW 8

#include "lib/temporal_denoise.wgsl"

var<private> block: array<f32, 256>;
var<private> origin: vec2<i32>;

fn cost(v: vec2<f32>) -> f32 {
    var s = 0.0;
    for (var j = 0; j < WINDOW; j++) {
        for (var i = 0; i < WINDOW; i++) {
            let uv = (vec2<f32>(origin + vec2<i32>(i, j)) + 0.5) * params.cur_texel + v;
            let d = block[j * WINDOW + i] - tdn_luma(textureSampleLevel(hist, hist_sampler, uv, 0.0));
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
            block[j * WINDOW + i] = tdn_luma(tdn_load(cur, origin + vec2<i32>(i, j)));
        }
    }
    var best = tdn_load(coarse, q).xy;
    var best_cost = cost(best);
    for (var k = 0; k < 4; k++) {
        let o = vec2<i32>(select(0, select(-1, 1, k == 1), k < 2), select(0, select(-1, 1, k == 3), k >= 2));
        let v = tdn_load(coarse, q + o).xy;
        let c = cost(v);
        if (c < best_cost) {
            best = v;
            best_cost = c;
        }
    }
    // One round of quarter-pixel steps around the best candidate, then a parabola
    // through the costs of the step's axis neighbours when the centre stayed best.
    let step = 0.25 * params.cur_texel;
    let centre = best;
    var costs = array<f32, 9>();
    costs[4] = best_cost;
    for (var k = 0; k < 9; k++) {
        if (k == 4) {
            continue;
        }
        let v = centre + vec2<f32>(f32(k % 3 - 1), f32(k / 3 - 1)) * step;
        let c = cost(v);
        costs[k] = c;
        if (c < best_cost) {
            best = v;
            best_cost = c;
        }
    }
    if (all(best == centre)) {
        let sub = vec2<f32>(tdn_parabola(costs[3], costs[4], costs[5]), tdn_parabola(costs[1], costs[4], costs[7]));
        best += sub * step;
    }
    return vec4<f32>(best, 0.0, 0.0);
}

// cs_main: TEXELS = 32 output texels (8 x 4) of LANES = 8 lanes. Workgroup
// memory: the texels' blocks, a cost and a vector per lane, and each texel's
// best vector and cost.
const LANES: i32 = 8;
var<workgroup> cs_block: array<f32, 2048>;
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
            let d = cs_block[(t * WINDOW + j) * WINDOW + i] - tdn_luma(textureSampleLevel(hist, hist_sampler, uv, 0.0));
            s += d * d;
        }
    }
    return s / f32(WINDOW * WINDOW);
}

// Candidate `k` of texel `t`: its vector and cost in the lane's slots.
fn cs_candidate(t: i32, k: i32, org: vec2<i32>, v: vec2<f32>) {
    cs_vec[t * LANES + k] = v;
    cs_cost[t * LANES + k] = cs_block_cost(t, org, v);
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

@compute @workgroup_size(8, 4, 8)
fn cs_main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
) {
    let o = vec2<i32>(id.xy);
    let q = min(o, vec2<i32>(params.out_size) - vec2<i32>(1));
    let lane = i32(local.z);
    let t = i32(local.y) * 8 + i32(local.x);
    let uvc = (vec2<f32>(q) + 0.5) / params.out_size;
    let org = vec2<i32>(floor(uvc * params.cur_size - 0.5 * f32(WINDOW) + 0.5));
    for (var i = lane; i < WINDOW * WINDOW; i += LANES) {
        cs_block[t * WINDOW * WINDOW + i] = tdn_luma(tdn_load(cur, org + vec2<i32>(i % WINDOW, i / WINDOW)));
    }
    workgroupBarrier();
    // The coarse level's vector at the block (lane 0: the best so far) and at
    // its four neighbours (lanes 1 to 4, slots 0 to 3).
    if (lane == 0) {
        let v = tdn_load(coarse, q).xy;
        cs_best[t] = v;
        cs_best_cost[t] = cs_block_cost(t, org, v);
    } else if (lane < 5) {
        let k = lane - 1;
        let off = vec2<i32>(select(0, select(-1, 1, k == 1), k < 2), select(0, select(-1, 1, k == 3), k >= 2));
        cs_candidate(t, k, org, tdn_load(coarse, q + off).xy);
    }
    cs_scan(t, lane, 4);
    // One round of quarter-pixel steps around it (slot m holds step k, k = 4
    // the centre left out).
    let step = 0.25 * params.cur_texel;
    let centre = cs_best[t];
    let centre_cost = cs_best_cost[t];
    let k = select(lane, lane + 1, lane >= 4);
    cs_candidate(t, lane, org, centre + vec2<f32>(f32(k % 3 - 1), f32(k / 3 - 1)) * step);
    cs_scan(t, lane, 8);
    if (lane != 0 || any(o != q)) {
        return;
    }
    var best = cs_best[t];
    if (all(best == centre)) {
        // Slots 3, 4 hold steps 3 (left), 5 (right); slots 1, 6 steps 1 (up), 7 (down).
        let c = t * LANES;
        let sub = vec2<f32>(
            tdn_parabola(cs_cost[c + 3], centre_cost, cs_cost[c + 4]),
            tdn_parabola(cs_cost[c + 1], centre_cost, cs_cost[c + 6]),
        );
        best += sub * step;
    }
    textureStore(out, o, vec4<f32>(best, 0.0, 0.0));
}
