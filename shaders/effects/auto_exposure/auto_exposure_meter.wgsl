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
#include "lib/reduce.wgsl"

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    min_ev: f32, // @default(-10) @range(-64, 64) lowest exposure value metered (EV relative to a scene averaging 0.18)
    max_ev: f32, // @default(10) @range(-64, 64) highest exposure value metered
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
    var sum = 0.0;
    var count = 0.0;
    for (var y = a0.y; y < a1.y; y++) {
        for (var x = a0.x; x < a1.x; x++) {
            let v = textureLoad(img, vec2<i32>(x, y), 0);
#if FIRST == 1
            let lum = dot(v.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
            let e = clamp(log2(max(lum, 1e-10) / 0.18), params.min_ev, params.max_ev);
            sum += e;
            count += 1.0;
#else
            sum += v.x * v.y;
            count += v.y;
#endif
        }
    }
    if (count > 0.0) {
        return vec4<f32>(sum / count, count, 0.0, 0.0);
    }
    return vec4<f32>(0.0);
}
