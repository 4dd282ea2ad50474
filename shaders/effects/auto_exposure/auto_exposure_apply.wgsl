// ae_apply: the exposed image of `auto_exposure` (effects/auto_exposure.fx):
// rgb * 2^(compensation - ev), ev the adapted exposure value (`state`, 1x1,
// r); alpha kept. A scene averaging luminance L (log-average) comes out averaging
// 0.18 * 2^compensation once adapted, within the EV limits.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var state: texture_2d<f32>;

struct Params {
    compensation: f32, // @default(0) @range(-16, 16) exposure compensation in EV: the adapted image averages 0.18 * 2^compensation
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    let ev = textureLoad(state, vec2<i32>(0), 0).r;
    return vec4<f32>(c.rgb * exp2(params.compensation - ev), c.a);
}
