// ae_meter: one level of the metering reduction of `auto_exposure`
// (effects/auto_exposure.fx). Each output texel i covers the input texels x with
// floor(x w / W) = i on each axis (W the input's size, w the output's; none when
// the output is the larger) and returns (mean, count) over them:
//   FIRST = 1: the input is the image; per pixel e = clamp(log2(Y / 0.18), min_ev,
//              max_ev) with Y = Rec. 709 luminance (linear light; at least 1e-10),
//              count = the number of pixels.
//   FIRST = 0: the input is the previous level's (mean, count): their weighted
//              mean and total count, so the last 1x1 level is the exact mean of e
//              over every pixel.
//
// Two entry points (docs/shaders.md, "Compute passes"): `cs_main`, 64
// invocations per output texel summing in a tree in workgroup memory
// (lib/reduce.wgsl), wherever the output can be a storage texture; `fs_main`,
// one invocation per output texel summing its footprint alone, where it cannot.
// They differ only in the order of the f32 sums.
#include "lib/reduce.wgsl"

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    min_ev: f32, // @default(-10) @range(-64, 64) lowest exposure value metered (EV relative to a scene averaging 0.18)
    max_ev: f32, // @default(10) @range(-64, 64) highest exposure value metered
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;
@group(0) @binding(2) var out: texture_storage_2d<rg32float, write>;

#define FIRST 0

// Texel `p`'s (sum, count): (e, 1) of a pixel, or a level's (mean * count, count).
fn meter_term(p: vec2<i32>) -> vec2<f32> {
    let v = textureLoad(img, p, 0);
#if FIRST == 1
    let lum = dot(v.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
    let e = clamp(log2(max(lum, 1e-10) / 0.18), params.min_ev, params.max_ev);
    return vec2<f32>(e, 1.0);
#else
    return vec2<f32>(v.x * v.y, v.y);
#endif
}

// (mean, count) of a (sum, count).
fn meter_result(t: vec2<f32>) -> vec4<f32> {
    if (t.y > 0.0) {
        return vec4<f32>(t.x / t.y, t.y, 0.0, 0.0);
    }
    return vec4<f32>(0.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let o = vec2<i32>(pos.xy);
    let n = vec2<i32>(textureDimensions(img));
    let area = lib_reduce_footprint(o, n, vec2<i32>(params.out_size));
    var t = vec2<f32>(0.0);
    for (var y = area.lo.y; y < area.hi.y; y++) {
        for (var x = area.lo.x; x < area.hi.x; x++) {
            t += meter_term(vec2<i32>(x, y));
        }
    }
    return meter_result(t);
}

@compute @workgroup_size(1, 1, 64)
fn cs_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let o = vec2<i32>(group.xy);
    let n = vec2<i32>(textureDimensions(img));
    let area = lib_reduce_footprint(o, n, vec2<i32>(params.out_size));
    var t = vec2<f32>(0.0);
    for (var i = i32(lane); i < lib_reduce_texels(area); i += LIB_REDUCE_LANES) {
        t += meter_term(lib_reduce_texel(area, i));
    }
    lib_reduce_partials[lane] = vec4<f32>(t, 0.0, 0.0);
    for (var s = u32(LIB_REDUCE_LANES / 2); s > 0u; s /= 2u) {
        workgroupBarrier();
        if (lane < s) {
            lib_reduce_partials[lane] += lib_reduce_partials[lane + s];
        }
    }
    if (lane == 0u) {
        textureStore(out, o, meter_result(lib_reduce_partials[0].xy));
    }
}
