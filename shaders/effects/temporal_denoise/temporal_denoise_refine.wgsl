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
