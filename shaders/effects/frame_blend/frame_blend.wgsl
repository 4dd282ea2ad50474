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

#define FRAMES 3

// Frame i: IN (0) or IN[-i].
fn frame(i: i32, p: vec2<i32>) -> vec4<f32> {
    switch i {
        case 0: { return textureLoad(f0, p, 0); }
        case 1: { return textureLoad(f1, p, 0); }
        case 2: { return textureLoad(f2, p, 0); }
        case 3: { return textureLoad(f3, p, 0); }
        case 4: { return textureLoad(f4, p, 0); }
        case 5: { return textureLoad(f5, p, 0); }
        case 6: { return textureLoad(f6, p, 0); }
        default: { return textureLoad(f7, p, 0); }
    }
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let w = params.weights;
    let v = params.weights_more;
    var weight = array<f32, 8>(w.x, w.y, w.z, w.w, v.x, v.y, v.z, v.w);
    var sum = weight[0] * frame(0, p);
    var total = weight[0];
    for (var i = 1; i < FRAMES; i++) {
        sum += weight[i] * frame(i, p);
        total += weight[i];
    }
    var k = params.scale;
    if (k == 0.0) {
        k = select(1.0 / total, 1.0, total == 0.0);
    }
    return k * sum;
}
