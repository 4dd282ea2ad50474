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

#include "lib/tdn.wgsl"

fn lanczos3(x: f32) -> f32 {
    let ax = abs(x);
    if (ax < 1e-4) {
        return 1.0;
    }
    if (ax >= 3.0) {
        return 0.0;
    }
    let px = 3.14159265 * x;
    return 3.0 * sin(px) * sin(px / 3.0) / (px * px);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = pos.xy / params.out_size;
    let v = tdn_field(mv, uv);
    let p = (uv + v) * params.out_size - 0.5;
    let inside = all(p >= vec2<f32>(-0.5)) && all(p <= params.out_size - 0.5);
    let i = vec2<i32>(floor(p));
    let f = p - floor(p);
    var wx: array<f32, 6>;
    var wy: array<f32, 6>;
    var sx = 0.0;
    var sy = 0.0;
    for (var k = 0; k < 6; k++) {
        wx[k] = lanczos3(f.x - f32(k - 2));
        wy[k] = lanczos3(f.y - f32(k - 2));
        sx += wx[k];
        sy += wy[k];
    }
    var sum = vec3<f32>(0.0);
    var lo = vec3<f32>(1e9);
    var hi = vec3<f32>(-1e9);
    var n = 0.0;
    for (var j = 0; j < 6; j++) {
        var row = vec3<f32>(0.0);
        for (var k = 0; k < 6; k++) {
            let t = tdn_load(hist, i + vec2<i32>(k - 2, j - 2));
            row += wx[k] * t.rgb;
            if (j == 2 || j == 3) && (k == 2 || k == 3) {
                lo = min(lo, t.rgb);
                hi = max(hi, t.rgb);
                let bx = select(1.0 - f.x, f.x, k == 3);
                let by = select(1.0 - f.y, f.y, j == 3);
                n += bx * by * t.a;
            }
        }
        sum += wy[j] * row;
    }
    sum = sum / (sx * sy);
    return vec4<f32>(clamp(sum, lo, hi), select(0.0, n, inside));
}
