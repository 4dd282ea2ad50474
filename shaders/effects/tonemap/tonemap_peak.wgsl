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
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, 64
// invocations per output texel combining in a tree in workgroup memory
// (lib/reduce.wgsl), wherever the output can be a storage texture; `fs_main`,
// one invocation per output texel over its footprint alone, where it cannot.
// They differ only in the order of the f32 sums (the max is exact).
#include "lib/transfer.wgsl"
#include "lib/reduce.wgsl"

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    exposure: f32, // @default(0) @range(-20, 20) exposure in stops applied before the curve
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var out: texture_storage_2d<rgba32float, write>;

#define FIRST 0

// Texel `p`'s (max, sum, count): a pixel's (pq, pq, 1), or a level's
// (max, mean * count, count).
fn peak_term(p: vec2<i32>) -> vec3<f32> {
    let v = textureLoad(img, p, 0);
#if FIRST == 1
    let c = lib_bt709_to_bt2020(v.rgb * exp2(params.exposure));
    // NaN and negative values count as black.
    let sig = max(max(c.r, max(c.g, c.b)), 0.0);
    let pq = lib_nits_to_pq(min(sig, 1e4) * 203.0);
    return vec3<f32>(pq, pq, 1.0);
#else
    return vec3<f32>(v.x, v.y * v.z, v.z);
#endif
}

// Two (max, sum, count) combined.
fn peak_add(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(max(a.x, b.x), a.y + b.y, a.z + b.z);
}

// (max, mean, count, 0) of a (max, sum, count).
fn peak_result(t: vec3<f32>) -> vec4<f32> {
    if (t.z > 0.0) {
        return vec4<f32>(t.x, t.y / t.z, t.z, 0.0);
    }
    return vec4<f32>(0.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let o = vec2<i32>(pos.xy);
    let n = vec2<i32>(textureDimensions(img));
    let area = lib_reduce_footprint(o, n, vec2<i32>(params.out_size));
    var t = vec3<f32>(0.0);
    for (var y = area.lo.y; y < area.hi.y; y++) {
        for (var x = area.lo.x; x < area.hi.x; x++) {
            t = peak_add(t, peak_term(vec2<i32>(x, y)));
        }
    }
    return peak_result(t);
}

@compute @workgroup_size(1, 1, 64)
fn cs_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let o = vec2<i32>(group.xy);
    let n = vec2<i32>(textureDimensions(img));
    let area = lib_reduce_footprint(o, n, vec2<i32>(params.out_size));
    var t = vec3<f32>(0.0);
    for (var i = i32(lane); i < lib_reduce_texels(area); i += LIB_REDUCE_LANES) {
        t = peak_add(t, peak_term(lib_reduce_texel(area, i)));
    }
    lib_reduce_partials[lane] = vec4<f32>(t, 0.0);
    for (var s = u32(LIB_REDUCE_LANES / 2); s > 0u; s /= 2u) {
        workgroupBarrier();
        if (lane < s) {
            let b = lib_reduce_partials[lane + s].xyz;
            lib_reduce_partials[lane] = vec4<f32>(peak_add(lib_reduce_partials[lane].xyz, b), 0.0);
        }
    }
    if (lane == 0u) {
        textureStore(out, o, peak_result(lib_reduce_partials[0].xyz));
    }
}
