// ae_adapt: the exposure of `auto_exposure` (effects/auto_exposure.fx) adapting
// over time. `meter` is the metered mean EV (1x1: mean, count), `last` this pass's
// own output one frame earlier (zero before the first frame). Output (1x1):
// r = the adapted EV, g = the time of this frame (seconds, the standard value
// `time`), b = 1 (a state is present), a = the target EV.
//
// target = clamp(metered mean, min_ev, max_ev). Without a state, or when the time
// did not advance (a still image, a restart), the EV is the target. Otherwise, with
// dt = time - the last time, it moves towards the target by at most speed_up * dt
// EV when rising (the scene got brighter) and speed_down * dt when falling.
@group(0) @binding(0) var meter: texture_2d<f32>;
@group(0) @binding(1) var last: texture_2d<f32>;

struct Params {
    speed_up: f32,   // @default(3) @range(0, 1000) EV per second the exposure follows a brighter scene
    speed_down: f32, // @default(1) @range(0, 1000) EV per second the exposure follows a darker scene
    min_ev: f32,     // @default(-10) @range(-64, 64) lowest exposure value (EV relative to a scene averaging 0.18)
    max_ev: f32,     // @default(10) @range(-64, 64) highest exposure value
    time: f32,
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    let m = textureLoad(meter, vec2<i32>(0), 0);
    let s = textureLoad(last, vec2<i32>(0), 0);
    let target_ev = clamp(m.x, params.min_ev, params.max_ev);
    let dt = params.time - s.y;
    var ev = target_ev;
    if (s.z > 0.5 && dt > 0.0) {
        let prev = clamp(s.x, params.min_ev, params.max_ev);
        ev = prev + clamp(target_ev - prev, -params.speed_down * dt, params.speed_up * dt);
    }
    return vec4<f32>(ev, params.time, 1.0, target_ev);
}
