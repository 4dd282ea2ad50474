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
@group(0) @binding(0) var blk: texture_2d<f32>;
@group(0) @binding(1) var last: texture_2d<f32>;

struct Params {
    sigma: f32, // @default(0) @range(0, 1) noise standard deviation (0..1 code values); 0: estimate it
    frame: u32,
}
@group(0) @binding(2) var<uniform> params: Params;

const QUANTILE: f32 = 0.2;

fn count_below(x: f32, use_all: bool) -> f32 {
    let s = vec2<i32>(textureDimensions(blk));
    var n = 0.0;
    for (var y = 0; y < s.y; y++) {
        for (var i = 0; i < s.x; i++) {
            let t = textureLoad(blk, vec2<i32>(i, y), 0);
            if ((use_all || t.g < 0.5) && t.r < x) {
                n += 1.0;
            }
        }
    }
    return n;
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    if (params.sigma > 0.0) {
        return vec4<f32>(params.sigma, 0.0, 0.0, 1.0);
    }
    let s = vec2<i32>(textureDimensions(blk));
    var valid = 0.0;
    var hi = 0.0;
    for (var y = 0; y < s.y; y++) {
        for (var i = 0; i < s.x; i++) {
            let t = textureLoad(blk, vec2<i32>(i, y), 0);
            if (t.g < 0.5) {
                valid += 1.0;
            }
            hi = max(hi, t.r);
        }
    }
    let use_all = valid < 8.0;
    let total = select(valid, f32(s.x * s.y), use_all);
    let want = QUANTILE * total;
    var lo = 0.0;
    hi = hi + 1e-6;
    for (var it = 0; it < 16; it++) {
        let mid = 0.5 * (lo + hi);
        if (count_below(mid, use_all) < want) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    var sigma = 0.5 * (lo + hi) / (6.0 * sqrt(2.0 / 3.14159265));
    let previous = textureLoad(last, vec2<i32>(0), 0).r;
    if (params.frame > 0u && previous > 0.0) {
        sigma = mix(previous, sigma, 0.25);
    }
    return vec4<f32>(sigma, 0.0, 0.0, 1.0);
}
