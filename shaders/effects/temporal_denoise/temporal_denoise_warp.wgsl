// tdn_warp: temporal_denoise's motion compensation (effects/temporal_denoise.fx):
// the filter's state of the previous frame (`hist`: rgb = the temporal average,
// a = the number of frames n it averages) resampled at uv + v, v = the motion
// field `mv` (uv units, bilinearly interpolated between its vectors).
//
// rgb: Lanczos-3 interpolation (6x6 texels, weights normalised; sharper than
// bicubic, so less blur builds up over the recursion), clamped to the range of
// the four nearest texels (no overshoot building up either).
// a: the same sample's n (bilinear weights of the four nearest texels), 0 where
// the sample lies more than half a pixel outside the frame (content entering at
// the edge has no history).
@group(0) @binding(0) var hist: texture_2d<f32>;
@group(0) @binding(1) var mv: texture_2d<f32>;

struct Params {
    out_size: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

#include "lib/temporal_denoise.wgsl"

// Lanczos-3 weights of the six taps at offsets -2..3 from floor(p), for the
// fraction f: L(x) = 3 sin(pi x) sin(pi x / 3) / (pi x)^2 at x = f + 2 - k. The
// sines of all six come from one sin/cos pair each: sin(pi (f + m)) = (-1)^m sin(pi f)
// and sin(pi (f + m) / 3) by the angle-sum formula. Normalised to sum 1.
fn lanczos_weights(f: f32, lo: ptr<function, vec3<f32>>, hi: ptr<function, vec3<f32>>) {
    let pi = 3.14159265;
    let x0 = vec3<f32>(f + 2.0, f + 1.0, f);
    let x1 = vec3<f32>(f - 1.0, f - 2.0, f - 3.0);
    let s1 = sin(pi * f);
    let a = pi * f / 3.0;
    let sa = sin(a);
    let ca = cos(a);
    // sin(a + m pi / 3) for m = 2, 1, 0, -1, -2, -3.
    let c60 = 0.5;
    let s60 = 0.8660254;
    let t0 = vec3<f32>(sa * -c60 + ca * s60, sa * c60 + ca * s60, sa);
    let t1 = vec3<f32>(sa * c60 - ca * s60, -sa * c60 - ca * s60, -sa);
    let sgn0 = vec3<f32>(1.0, -1.0, 1.0);
    let sgn1 = vec3<f32>(-1.0, 1.0, -1.0);
    var w0 = 3.0 * s1 * sgn0 * t0 / max(pi * pi * x0 * x0, vec3<f32>(1e-8));
    var w1 = 3.0 * s1 * sgn1 * t1 / max(pi * pi * x1 * x1, vec3<f32>(1e-8));
    if (abs(f) < 1e-4) {
        w0 = vec3<f32>(0.0, 0.0, 1.0);
        w1 = vec3<f32>(0.0);
    }
    let total = dot(w0, vec3<f32>(1.0)) + dot(w1, vec3<f32>(1.0));
    *lo = w0 / total;
    *hi = w1 / total;
}

// One row y of the 6x6 footprint: columns x0, x1 weighted by w0, w1.
fn row(y: i32, x0: vec3<i32>, x1: vec3<i32>, w0: vec3<f32>, w1: vec3<f32>) -> vec3<f32> {
    return w0.x * textureLoad(hist, vec2<i32>(x0.x, y), 0).rgb
        + w0.y * textureLoad(hist, vec2<i32>(x0.y, y), 0).rgb
        + w0.z * textureLoad(hist, vec2<i32>(x0.z, y), 0).rgb
        + w1.x * textureLoad(hist, vec2<i32>(x1.x, y), 0).rgb
        + w1.y * textureLoad(hist, vec2<i32>(x1.y, y), 0).rgb
        + w1.z * textureLoad(hist, vec2<i32>(x1.z, y), 0).rgb;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = pos.xy / params.out_size;
    let v = tdn_field(mv, uv);
    let p = (uv + v) * params.out_size - 0.5;
    let inside = all(p >= vec2<f32>(-0.5)) && all(p <= params.out_size - 0.5);
    let i = vec2<i32>(floor(p));
    let f = p - floor(p);
    var wx0: vec3<f32>;
    var wx1: vec3<f32>;
    var wy0: vec3<f32>;
    var wy1: vec3<f32>;
    lanczos_weights(f.x, &wx0, &wx1);
    lanczos_weights(f.y, &wy0, &wy1);
    // Texel coordinates of the 6x6 footprint, clamped once per row and column.
    let last = vec2<i32>(params.out_size) - 1;
    let x0 = clamp(vec3<i32>(i.x) + vec3<i32>(-2, -1, 0), vec3<i32>(0), vec3<i32>(last.x));
    let x1 = clamp(vec3<i32>(i.x) + vec3<i32>(1, 2, 3), vec3<i32>(0), vec3<i32>(last.x));
    let y0 = clamp(vec3<i32>(i.y) + vec3<i32>(-2, -1, 0), vec3<i32>(0), vec3<i32>(last.y));
    let y1 = clamp(vec3<i32>(i.y) + vec3<i32>(1, 2, 3), vec3<i32>(0), vec3<i32>(last.y));
    let sum = wy0.x * row(y0.x, x0, x1, wx0, wx1) + wy0.y * row(y0.y, x0, x1, wx0, wx1)
        + wy0.z * row(y0.z, x0, x1, wx0, wx1) + wy1.x * row(y1.x, x0, x1, wx0, wx1)
        + wy1.y * row(y1.y, x0, x1, wx0, wx1) + wy1.z * row(y1.z, x0, x1, wx0, wx1);
    let xs = vec2<i32>(x0.z, x1.x);
    let ys = vec2<i32>(y0.z, y1.x);
    var lo = vec3<f32>(1e9);
    var hi = vec3<f32>(-1e9);
    var n = 0.0;
    for (var k = 0; k < 4; k++) {
        let dx = k & 1;
        let dy = k >> 1;
        let t = textureLoad(hist, vec2<i32>(xs[dx], ys[dy]), 0);
        lo = min(lo, t.rgb);
        hi = max(hi, t.rgb);
        let bx = select(1.0 - f.x, f.x, dx == 1);
        let by = select(1.0 - f.y, f.y, dy == 1);
        n += bx * by * t.a;
    }
    return vec4<f32>(clamp(sum, lo, hi), select(0.0, n, inside));
}
