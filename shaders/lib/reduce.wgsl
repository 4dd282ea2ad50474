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

// The same reduction as a compute pass (docs/shaders.md, "Compute passes"):
// `@compute @workgroup_size(1, 1, 64)` gives each output texel a workgroup of
// LIB_REDUCE_LANES invocations. Lane `l` takes the footprint's texels l,
// l + 64, ... (row-major: `lib_reduce_texel`), stores its partial result in
// `lib_reduce_partials[l]`, and the shader combines the 64 in a tree there
// (halving the lanes after each workgroupBarrier).
const LIB_REDUCE_LANES: i32 = 64;
var<workgroup> lib_reduce_partials: array<vec4<f32>, 64>;

// The number of texels under a footprint.
fn lib_reduce_texels(area: LibFootprint) -> i32 {
    let s = max(area.hi - area.lo, vec2<i32>(0));
    return s.x * s.y;
}

// The `i`-th texel of a footprint, row-major.
fn lib_reduce_texel(area: LibFootprint, i: i32) -> vec2<i32> {
    let w = area.hi.x - area.lo.x;
    return area.lo + vec2<i32>(i % w, i / w);
}
