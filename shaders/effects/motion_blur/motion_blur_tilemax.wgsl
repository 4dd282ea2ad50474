// mb_tilemax: one axis of the tile-max velocity reduction of `motion_blur`
// (effects/motion_blur.fx). Each output texel i covers the input texels x with
// floor(x w / W) = i, that is [ceil(i W / w), ceil((i + 1) W / w)), along the axis
// AXIS (0: x, 1: y; W the input's size, w the output's) and returns the longest of their motion vectors
// (pixels; the first of equal lengths). Run once per axis: tiles of the motion
// image, each the longest vector of its rectangle of pixels.
@group(0) @binding(0) var motion: texture_2d<f32>;

struct Params {
    out_size: vec2<f32>,
}
@group(0) @binding(1) var<uniform> params: Params;

#define AXIS 0

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let o = vec2<i32>(pos.xy);
    let size_in = vec2<i32>(textureDimensions(motion));
    let size_out = vec2<i32>(params.out_size);
#if AXIS == 0
    let a0 = min((o.x * size_in.x + size_out.x - 1) / size_out.x, size_in.x - 1);
    let a1 = max(((o.x + 1) * size_in.x + size_out.x - 1) / size_out.x, a0 + 1);
    let step = vec2<i32>(1, 0);
    let start = vec2<i32>(a0, min(o.y, size_in.y - 1));
#else
    let a0 = min((o.y * size_in.y + size_out.y - 1) / size_out.y, size_in.y - 1);
    let a1 = max(((o.y + 1) * size_in.y + size_out.y - 1) / size_out.y, a0 + 1);
    let step = vec2<i32>(0, 1);
    let start = vec2<i32>(min(o.x, size_in.x - 1), a0);
#endif
    var best = vec2<f32>(0.0);
    var best_len = -1.0;
    for (var i = 0; i < a1 - a0; i++) {
        let v = textureLoad(motion, start + step * i, 0).xy;
        let l = dot(v, v);
        if (l > best_len) {
            best_len = l;
            best = v;
        }
    }
    return vec4<f32>(best, 0.0, 0.0);
}
