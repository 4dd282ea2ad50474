// tonemap_peak_adapt: the source peak of `tonemap`'s BT.2390 EETF measured over
// time (effects/tonemap.fx), libplacebo's scheme. `meter` is the frame's (peak,
// average) in PQ codes (1x1), `last` this pass's own output one frame earlier
// (zero before the first frame). Output (1x1): r = the smoothed peak (PQ code),
// g = the smoothed average (PQ code), b = 1 (a state is present), a = the frame
// number.
//
// Smoothing: an exponential moving average in the PQ domain with coefficient
// 1 / smoothing (frames; 1 = no smoothing). Scene cuts: when the frame's average
// differs from the smoothed one by more than scene_high (in % of the PQ range) the
// state restarts from this frame; between scene_low and scene_high it moves there
// in proportion. The first frame, a still, or a frame number that did not advance
// (a restart) take the measurement as it is.
@group(0) @binding(0) var meter: texture_2d<f32>;
@group(0) @binding(1) var last: texture_2d<f32>;

struct Params {
    smoothing: f32,  // @default(20) @range(1, 1000) frames over which the measured peak is averaged
    scene_low: f32,  // @default(1) @range(0, 100) average-brightness change (% PQ) where a scene cut starts to count
    scene_high: f32, // @default(3) @range(0, 100) average-brightness change (% PQ) that resets the peak (a scene cut)
    frame: f32,
}
@group(0) @binding(2) var<uniform> params: Params;

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    let m = textureLoad(meter, vec2<i32>(0), 0);
    let s = textureLoad(last, vec2<i32>(0), 0);
    if (s.z < 0.5 || params.frame <= s.w) {
        return vec4<f32>(m.x, m.y, 1.0, params.frame);
    }
    var k = 1.0 / max(params.smoothing, 1.0);
    let delta = abs(m.y - s.y) * 100.0;
    if (delta > params.scene_low) {
        let t = clamp((delta - params.scene_low) / max(params.scene_high - params.scene_low, 1e-6), 0.0, 1.0);
        k = mix(k, 1.0, t);
    }
    return vec4<f32>(mix(s.x, m.x, k), mix(s.y, m.y, k), 1.0, params.frame);
}
