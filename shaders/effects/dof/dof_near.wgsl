// dof_near: gather of the near field (CoC < 0) and the final composite (used by the
// `dof` effect).
//
// R = nearmax(p) (shaders/effects/dof/dof_nearmax.wgsl): the largest near-field CoC radius in the
// neighbourhood. R < 0.5: out = far(p). Otherwise SAMPLES taps on a golden-angle
// spiral filling the disc of radius R, rounded to texels q (clamped to the image) at
// distance r_q; a near-field tap (c_q <= -0.5, radius a_q = -c_q) covers p with
// cov_q = clamp(a_q - r_q + 0.5, 0, 1), weight w_q = cov_q / a_q^2:
//   near colour  N = sum w_q img(q) / sum w_q
//   coverage     alpha = clamp(sum w_q / sum_i clamp(R - r_i + 0.5, 0, 1) / R^2, 0, 1)
// (the denominator is the weight a uniform near field of CoC R would collect, so a
// pixel inside a blurred foreground gets alpha = 1, one at its silhouette about 1/2,
// and the blurred foreground spreads over the sharp pixels behind it);
//   out = mix(far(p), N, alpha)
#define SAMPLES 48

@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var coc: texture_2d<f32>;
@group(0) @binding(2) var far: texture_2d<f32>;
@group(0) @binding(3) var nearmax: texture_2d<f32>;

#include "lib/dof.wgsl"

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(img)) - 1;
    let f = textureLoad(far, p, 0);
    let R = textureLoad(nearmax, p, 0).r;
    if (!(R >= 0.5)) {
        return f;
    }
    var sum = vec4<f32>(0.0);
    var total = 0.0;
    var full = 0.0;
    for (var i = 0; i < SAMPLES; i++) {
        let q = lib_disc_tap(p, hi, R, i, SAMPLES);
        let dist = length(vec2<f32>(q - p));
        full += clamp(R - dist + 0.5, 0.0, 1.0);
        let cq = textureLoad(coc, q, 0).r;
        if (cq > -0.5) {
            continue;
        }
        let a = -cq;
        let w = clamp(a - dist + 0.5, 0.0, 1.0) / (a * a);
        sum += w * textureLoad(img, q, 0);
        total += w;
    }
    if (!(total > 0.0)) {
        return f;
    }
    let alpha = clamp(total * R * R / max(full, 1e-6), 0.0, 1.0);
    return mix(f, sum / total, alpha);
}
