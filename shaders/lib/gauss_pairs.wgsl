// Gaussian weights taken two at a time, for blurs that fetch two texels per
// bilinear tap (shaders/effects/gaussian_blur/gaussian_blur.wgsl, pencil_blur.wgsl, lib/blur_axis.wgsl):
// `#include "lib/gauss_pairs.wgsl"`.
//
// w(i) = q^(i*i), q = exp(-1 / (2 sigma^2)), computed by products (no exp per
// tap): w(i+1) = w(i) * q^(2i+1).

// The running state: `w` = the weight of the next tap, `step` = the ratio to the
// one after it, `q2` = q^2.
struct LibGaussPairs {
    w: f32,
    step: f32,
    q2: f32,
}

// The state before tap 1: w(1) = q, w(2) / w(1) = q^3.
fn lib_gauss_pairs(sigma: f32) -> LibGaussPairs {
    let q = exp(-0.5 / (sigma * sigma));
    let q2 = q * q;
    return LibGaussPairs(q, q * q2, q2);
}

// The weights (w(i), w(i+1)) of taps i and i+1, w(i+1) = 0 past the radius `r`,
// and the state advanced two steps: w(i+2) = w(i+1) * q^(2i+3).
fn lib_gauss_next_pair(g: ptr<function, LibGaussPairs>, i: i32, r: i32) -> vec2<f32> {
    let w1 = (*g).w;
    var w2 = w1 * (*g).step;
    if (i + 1 > r) {
        w2 = 0.0;
    }
    (*g).w = w2 * (*g).step * (*g).q2;
    (*g).step = (*g).step * (*g).q2 * (*g).q2;
    return vec2<f32>(w1, w2);
}
