// The lanes of temporal_denoise's staged motion search (the `cs_main` entry
// points of temporal_denoise_match.wgsl and temporal_denoise_refine.wgsl):
// candidate slots and the scan that keeps the best. The including shader
// declares `LANES`, the workgroup arrays `cs_vec`, `cs_cost` (LANES slots per
// texel), `cs_best`, `cs_best_cost` (one per texel) and
// `fn cs_block_cost(t, org, v) -> f32`. `#include "lib/temporal_denoise_lanes.wgsl"`.

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
