// tdn_warp: temporal_denoise's motion compensation (effects/temporal_denoise.fx):
// the filter's state of the previous frame (`hist`: rgb = the temporal average,
// a = the number of frames n it averages) resampled at uv + v, v = the motion
// field `mv` (uv units, bilinearly interpolated between its vectors).
//
// rgb: Catmull-Rom (bicubic) interpolation, clamped to the range of the four
// nearest texels (no overshoot, which would build up over the recursion).
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

fn cr_weights(t: f32) -> vec4<f32> {
    let t2 = t * t;
    let t3 = t2 * t;
    return vec4<f32>(
        -0.5 * t3 + t2 - 0.5 * t,
        1.5 * t3 - 2.5 * t2 + 1.0,
        -1.5 * t3 + 2.0 * t2 + 0.5 * t,
        0.5 * t3 - 0.5 * t2,
    );
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let uv = pos.xy / params.out_size;
    let v = tdn_field(mv, uv);
    let p = (uv + v) * params.out_size - 0.5;
    let inside = all(p >= vec2<f32>(-0.5)) && all(p <= params.out_size - 0.5);
    let i = vec2<i32>(floor(p));
    let f = p - floor(p);
    let wx = cr_weights(f.x);
    let wy = cr_weights(f.y);
    var sum = vec3<f32>(0.0);
    var lo = vec3<f32>(1e9);
    var hi = vec3<f32>(-1e9);
    var n = 0.0;
    for (var j = 0; j < 4; j++) {
        var row = vec3<f32>(0.0);
        for (var k = 0; k < 4; k++) {
            let t = tdn_load(hist, i + vec2<i32>(k - 1, j - 1));
            row += wx[k] * t.rgb;
            if (j == 1 || j == 2) && (k == 1 || k == 2) {
                lo = min(lo, t.rgb);
                hi = max(hi, t.rgb);
                let bx = select(1.0 - f.x, f.x, k == 2);
                let by = select(1.0 - f.y, f.y, j == 2);
                n += bx * by * t.a;
            }
        }
        sum += wy[j] * row;
    }
    return vec4<f32>(clamp(sum, lo, hi), select(0.0, n, inside));
}
