// tmix: weighted mean of the current and up to 7 earlier frames (the `frame_blend`
// effect; see effects/frame_blend.fx).
//
//   out = k * sum_{i < FRAMES} w_i * f_i,   f_i = IN[-i] (clamped at the first frame)
//   k   = scale, or 1 / sum_{i < FRAMES} w_i when scale = 0 (1 if that sum is 0)
// w_0..w_3 = weights, w_4..w_7 = weights_more (newest first). All four channels.
@group(0) @binding(0) var f0: texture_2d<f32>;
@group(0) @binding(1) var f1: texture_2d<f32>;
@group(0) @binding(2) var f2: texture_2d<f32>;
@group(0) @binding(3) var f3: texture_2d<f32>;
@group(0) @binding(4) var f4: texture_2d<f32>;
@group(0) @binding(5) var f5: texture_2d<f32>;
@group(0) @binding(6) var f6: texture_2d<f32>;
@group(0) @binding(7) var f7: texture_2d<f32>;

struct Params {
    weights: vec4<f32>,      // @default(1, 1, 1, 1) @range(-16, 16) weights of IN, IN[-1], IN[-2], IN[-3]
    weights_more: vec4<f32>, // @default(1, 1, 1, 1) @range(-16, 16) weights of IN[-4] .. IN[-7]
    scale: f32,              // @default(0) @range(0, 32767) factor of the weighted sum; 0: 1 / (sum of the weights)
}
@group(0) @binding(8) var<uniform> params: Params;

#ifndef FRAMES
#define FRAMES 3
#endif

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let w = params.weights;
    let v = params.weights_more;
    var sum = w.x * textureLoad(f0, p, 0);
    var total = w.x;
#if FRAMES >= 2
    sum += w.y * textureLoad(f1, p, 0);
    total += w.y;
#endif
#if FRAMES >= 3
    sum += w.z * textureLoad(f2, p, 0);
    total += w.z;
#endif
#if FRAMES >= 4
    sum += w.w * textureLoad(f3, p, 0);
    total += w.w;
#endif
#if FRAMES >= 5
    sum += v.x * textureLoad(f4, p, 0);
    total += v.x;
#endif
#if FRAMES >= 6
    sum += v.y * textureLoad(f5, p, 0);
    total += v.y;
#endif
#if FRAMES >= 7
    sum += v.z * textureLoad(f6, p, 0);
    total += v.z;
#endif
#if FRAMES >= 8
    sum += v.w * textureLoad(f7, p, 0);
    total += v.w;
#endif
    var k = params.scale;
    if (k == 0.0) {
        k = select(1.0 / total, 1.0, total == 0.0);
    }
    return k * sum;
}
