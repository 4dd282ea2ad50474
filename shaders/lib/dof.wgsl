// The disc of the depth-of-field gathers (shaders/effects/dof/dof_far.wgsl, dof_near.wgsl):
// `#include "lib/dof.wgsl"`.

// Sample `i` of `n` of a disc of `radius` pixels about texel `p`: a golden-angle
// spiral (even density over the disc), rounded to a texel and clamped to
// [0, hi].
fn lib_disc_tap(p: vec2<i32>, hi: vec2<i32>, radius: f32, i: i32, n: i32) -> vec2<i32> {
    let fi = f32(i);
    let r = radius * sqrt((fi + 0.5) / f32(n));
    let a = fi * 2.39996323;
    return clamp(p + vec2<i32>(round(r * vec2<f32>(cos(a), sin(a)))), vec2<i32>(0), hi);
}
