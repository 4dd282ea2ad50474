// trail: feedback decay for the `motion_trail` effect (effects/motion_trail.fx).
//
//   MODE 0 (max):  out = max(cur, decay * prev)
//   MODE 1 (add):  out = cur + decay * prev      (alpha: min(cur.a + decay * prev.a, 1))
// prev = this pass's output of the previous frame (zero before the first frame).
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var prev: texture_2d<f32>;

struct Params {
    decay: f32, // @default(0.8) @range(0, 1) fraction of the trail kept from one frame to the next
}
@group(0) @binding(2) var<uniform> params: Params;

#define MODE 0

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let c = textureLoad(cur, p, 0);
    let h = params.decay * textureLoad(prev, p, 0);
#if MODE == 0
    return max(c, h);
#else
    let s = c + h;
    return vec4<f32>(s.rgb, min(s.a, 1.0));
#endif
}
