// dof_far: gather blur of the far field and the in-focus pixels (used by the `dof`
// effect); the near field is shaders/effects/dof/dof_near.wgsl.
//
// For a pixel p with CoC c_p (shaders/effects/dof/dof_coc.wgsl, pixels):
//   |c_p| < 0.5 (in focus): out = img(p), exactly.
//   c_p <= -0.5 (near field): the background behind it, for the near field's
//   semi-transparent edges: the mean of the taps (as below, disc of radius -c_p)
//   that are not in the near field; img(p) if there is none.
//   c_p >= 0.5: SAMPLES taps on a golden-angle spiral filling the disc of radius c_p,
//   each rounded to a texel q (clamped to the image), at distance r_q = |q - p|;
//   near-field taps (c_q < 0) are skipped; a tap's effective CoC is
//       e_q = min(c_q, c_p)
//   (in the far field the CoC grows with depth, so a tap behind p is limited to p's
//   CoC, and a sharper tap in front of p keeps its own: a sharp foreground, c = 0,
//   never spreads onto the background around it: no halo); it covers p with
//       cov_q = clamp(e_q - r_q + 0.5, 0, 1)
//   and weighs w_q = cov_q / max(e_q, 0.5)^2 (its light spread over its disc).
//   out = (img(p) / c_p^2 + sum w_q img(q)) / (1 / c_p^2 + sum w_q)   (all four channels)
// Texels are read with textureLoad (no bilinear mixing across silhouettes).
#define SAMPLES 48

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var coc: texture_2d<f32>;

#include "lib/dof.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(img)) - 1;
    let c0 = textureLoad(img, p, 0);
    let cp = textureLoad(coc, p, 0).r;
    if (cp <= -0.5) {
        var bg = vec4<f32>(0.0);
        var count = 0.0;
        for (var i = 0; i < SAMPLES; i++) {
            let q = lib_disc_tap(p, hi, -cp, i, SAMPLES);
            if (textureLoad(coc, q, 0).r >= 0.0) {
                bg += textureLoad(img, q, 0);
                count += 1.0;
            }
        }
        return select(c0, bg / max(count, 1.0), count > 0.0);
    }
    if (!(cp >= 0.5)) {
        return c0;
    }
    let w0 = 1.0 / (cp * cp);
    var sum = c0 * w0;
    var total = w0;
    for (var i = 0; i < SAMPLES; i++) {
        let q = lib_disc_tap(p, hi, cp, i, SAMPLES);
        if (all(q == p)) {
            continue;
        }
        let cq = textureLoad(coc, q, 0).r;
        if (cq < 0.0) {
            continue;
        }
        let e = min(cq, cp);
        let cov = clamp(e - length(vec2<f32>(q - p)) + 0.5, 0.0, 1.0);
        let me = max(e, 0.5);
        let w = cov / (me * me);
        sum += w * textureLoad(img, q, 0);
        total += w;
    }
    return sum / total;
}
