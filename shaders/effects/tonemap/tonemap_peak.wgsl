// tonemap_peak: one level of the peak measurement of `tonemap`'s BT.2390 EETF
// (effects/tonemap.fx), a reduction. Each output texel i covers the input texels
// x with floor(x w / W) = i on each axis (W the input's size, w the output's) and
// returns (max, mean, count, 0) over them:
//   FIRST = 1: the input is the image; per pixel the signal is the PQ code of its
//              largest BT.2020 component (linear working-space BT.709 converted,
//              at 1.0 = 203 cd/m²), after `exposure`; count = 1 per pixel.
//   FIRST = 0: the input is the previous level's (max, mean, count): their max,
//              weighted mean and total count, so the last 1x1 level holds the
//              frame's peak and average PQ brightness.
#include "lib/transfer.wgsl"

#include "lib/reduce.wgsl"

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    exposure: f32, // @default(0) @range(-20, 20) exposure in stops applied before the curve
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;

#define FIRST 0

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let o = vec2<i32>(pos.xy);
    let n = vec2<i32>(textureDimensions(img));
    let area = lib_reduce_footprint(o, n, vec2<i32>(params.out_size));
    let a0 = area.lo;
    let a1 = area.hi;
    var peak = 0.0;
    var sum = 0.0;
    var count = 0.0;
    for (var y = a0.y; y < a1.y; y++) {
        for (var x = a0.x; x < a1.x; x++) {
            let v = textureLoad(img, vec2<i32>(x, y), 0);
#if FIRST == 1
            let c = lib_bt709_to_bt2020(v.rgb * exp2(params.exposure));
            // NaN and negative values count as black.
            let sig = max(max(c.r, max(c.g, c.b)), 0.0);
            let pq = lib_nits_to_pq(min(sig, 1e4) * 203.0);
            peak = max(peak, pq);
            sum += pq;
            count += 1.0;
#else
            peak = max(peak, v.x);
            sum += v.y * v.z;
            count += v.z;
#endif
        }
    }
    if (count > 0.0) {
        return vec4<f32>(peak, sum / count, count, 0.0);
    }
    return vec4<f32>(0.0);
}
