// taa_out: the output of the `taa` effect (effects/taa.fx): the resolved colour of
// the state (rgb) with the current frame's alpha. VIEW 1 shows the history
// length instead: n / frames as grey (1: a full history, 0: none).
@group(0) @binding(0) var state: texture_2d<f32>;
@group(0) @binding(1) var cur: texture_2d<f32>;

struct Params {
    frames: f32, // @default(10) @range(1, 64) most frames the history stands for (for VIEW 1)
}
@group(0) @binding(2) var<uniform> params: Params;

#define VIEW 0

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let s = textureLoad(state, p, 0);
#if VIEW == 1
    let v = s.a / params.frames;
    return vec4<f32>(v, v, v, 1.0);
#else
    return vec4<f32>(s.rgb, textureLoad(cur, p, 0).a);
#endif
}
