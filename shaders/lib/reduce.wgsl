// Reductions by levels (auto_exposure's metering, tonemap's peak measurement):
// `#include "lib/reduce.wgsl"`.
//
// Output texel `o` of a level `w` texels wide covers the input texels x (input
// `n` texels wide) with floor(x w / n) = o on each axis: [lo, hi). Every input
// texel belongs to exactly one output texel; none when the output is the larger.
struct LibFootprint {
    lo: vec2<i32>,
    hi: vec2<i32>,
}

fn lib_reduce_footprint(o: vec2<i32>, n: vec2<i32>, w: vec2<i32>) -> LibFootprint {
    let lo = (o * n + w - vec2<i32>(1)) / w;
    let hi = min(((o + vec2<i32>(1)) * n + w - vec2<i32>(1)) / w, n);
    return LibFootprint(lo, hi);
}
