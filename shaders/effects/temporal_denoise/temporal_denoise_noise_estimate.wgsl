// tdn_noise_est: last step of temporal_denoise's noise estimate
// (effects/temporal_denoise.fx), a 1x1 pass. Over the blocks of tdn_noise_blk that
// are not clipped (all blocks if fewer than 8 are), the QUANTILE-th quantile q of
// the block means of |N * I| (found by bisection): textured blocks read high, the
// flattest blocks read the noise. sigma = q / (6 sqrt(2 / pi)). (For pure noise
// the quantile lies a little below the mean of the blocks: tests/effects/temporal_denoise.rs
// measures the estimate within 3% of the true sigma at 4/255 and 12/255.)
// The estimate is smoothed over time: mix(previous, new, 0.25) after the first
// frame (`last` = this pass's previous output). A `sigma` parameter above 0 is
// used as it is.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, one workgroup
// of LANES invocations for the one output texel (`@workgroup_size(LANES, 1)`:
// lane 0 is the texel, the others lie past the edge and only count), wherever
// the output can be a storage texture, on both execution paths: lane l takes the
// blocks l, l + LANES, ... (row-major), and at each bisection step the lanes'
// counts below the midpoint are summed in a tree in workgroup memory, so every
// lane takes the same next interval; `fs_main`, one invocation counting every
// block at every step, where the output cannot be a storage texture. The counts
// are integers and the maximum is exact: the two give the same value
// (tests/compute_native.rs). The lanes lie along x, not z as the other
// reductions' (lanes per texel, drawn under fragment execution): an NVIDIA
// H200 allows at most 64 invocations along z, and `@workgroup_size(1, 1, 256)`
// fell back to this file's single-invocation fragment entry there (20.5 ms a
// 1080p frame, bench/gpu.sh). So it is dispatched on both paths; on lavapipe that
// costs about 4 ms a 1080p frame more than the drawn entry.
@group(0) @binding(0) var blk: texture_2d<f32>;
@group(0) @binding(1) var last: texture_2d<f32>;

struct Params {
    sigma: f32, // @default(0) @range(0, 1) noise standard deviation (0..1 code values); 0: estimate it
    frame: u32,
}
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var out: texture_storage_2d<r32float, write>;

const QUANTILE: f32 = 0.2;
const STEPS: i32 = 16;

// Block `i` of the row-major order, `w` blocks a row.
fn block(i: i32, w: i32) -> vec4<f32> {
    return textureLoad(blk, vec2<i32>(i % w, i / w), 0);
}

// The number of blocks first, first + stride, ... (row-major) that are not
// clipped (r) and the largest block mean among them all, clipped or not (g).
fn scan_blocks(first: i32, stride: i32) -> vec2<f32> {
    let s = vec2<i32>(textureDimensions(blk));
    var valid = 0u;
    var hi = 0.0;
    for (var i = first; i < s.x * s.y; i += stride) {
        let t = block(i, s.x);
        if (t.g < 0.5) {
            valid += 1u;
        }
        hi = max(hi, t.r);
    }
    return vec2<f32>(f32(valid), hi);
}

// The number of blocks first, first + stride, ... below x (not clipped ones
// only, unless use_all).
fn count_below(x: f32, use_all: bool, first: i32, stride: i32) -> u32 {
    let s = vec2<i32>(textureDimensions(blk));
    var n = 0u;
    for (var i = first; i < s.x * s.y; i += stride) {
        let t = block(i, s.x);
        if ((use_all || t.g < 0.5) && t.r < x) {
            n += 1u;
        }
    }
    return n;
}

// The quantile wanted: QUANTILE of the blocks counted (every block if fewer
// than 8 are not clipped).
fn wanted(valid: f32, use_all: bool) -> f32 {
    let s = vec2<i32>(textureDimensions(blk));
    return QUANTILE * select(valid, f32(s.x * s.y), use_all);
}

// The output texel from the final interval [lo, hi]: smoothed with the
// previous frame's estimate.
fn estimate(lo: f32, hi: f32) -> vec4<f32> {
    var sigma = 0.5 * (lo + hi) / (6.0 * sqrt(2.0 / 3.14159265));
    let previous = textureLoad(last, vec2<i32>(0), 0).r;
    if (params.frame > 0u && previous > 0.0) {
        sigma = mix(previous, sigma, 0.25);
    }
    return vec4<f32>(sigma, 0.0, 0.0, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    if (params.sigma > 0.0) {
        return vec4<f32>(params.sigma, 0.0, 0.0, 1.0);
    }
    let scan = scan_blocks(0, 1);
    let use_all = scan.x < 8.0;
    let want = wanted(scan.x, use_all);
    var lo = 0.0;
    var hi = scan.y + 1e-6;
    for (var it = 0; it < STEPS; it++) {
        let mid = 0.5 * (lo + hi);
        let below = f32(count_below(mid, use_all, 0, 1)) < want;
        lo = select(lo, mid, below);
        hi = select(mid, hi, below);
    }
    return estimate(lo, hi);
}

const LANES: u32 = 256u;
var<workgroup> cs_count: array<u32, 256>;
var<workgroup> cs_max: array<f32, 256>;

// The sum of the lanes' `n` and the largest of their `m`, the same in every
// lane: a tree in workgroup memory (halving the lanes after each barrier).
fn cs_reduce(lane: u32, n: u32, m: f32) -> vec2<f32> {
    cs_count[lane] = n;
    cs_max[lane] = m;
    for (var s = LANES / 2u; s > 0u; s /= 2u) {
        workgroupBarrier();
        if (lane < s) {
            cs_count[lane] += cs_count[lane + s];
            cs_max[lane] = max(cs_max[lane], cs_max[lane + s]);
        }
    }
    workgroupBarrier();
    let r = vec2<f32>(f32(cs_count[0]), cs_max[0]);
    // Every lane has read the sums before the next reduction overwrites them.
    workgroupBarrier();
    return r;
}

@compute @workgroup_size(256, 1, 1)
fn cs_main(@builtin(local_invocation_index) lane: u32) {
    if (params.sigma > 0.0) {
        if (lane == 0u) {
            textureStore(out, vec2<i32>(0), vec4<f32>(params.sigma, 0.0, 0.0, 1.0));
        }
        return;
    }
    let first = i32(lane);
    let stride = i32(LANES);
    let mine = scan_blocks(first, stride);
    let scan = cs_reduce(lane, u32(mine.x), mine.y);
    let use_all = scan.x < 8.0;
    let want = wanted(scan.x, use_all);
    var lo = 0.0;
    var hi = scan.y + 1e-6;
    for (var it = 0; it < STEPS; it++) {
        let mid = 0.5 * (lo + hi);
        let below = cs_reduce(lane, count_below(mid, use_all, first, stride), 0.0).x < want;
        lo = select(lo, mid, below);
        hi = select(mid, hi, below);
    }
    if (lane == 0u) {
        textureStore(out, vec2<i32>(0), estimate(lo, hi));
    }
}
