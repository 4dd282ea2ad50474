// auto_exposure: automatic exposure of HDR frames, adapting over time like an eye
// or a camera. Its output is the exposed image, to feed tonemap:
// `fxrun auto_exposure tonemap -i 'in/%04d.exr' -o 'out/%04d.png'`.
//
// Exposure values: EV here is relative to middle grey, ev = log2(L / 0.18) for a
// scene whose log-average luminance is L (EV 0: a scene averaging 0.18 passes
// unchanged; +1: twice as bright). The output is the input times
// 2^(compensation - ev): once adapted, a scene comes out averaging (log-average)
// 0.18 * 2^compensation, unless its EV is beyond min_ev / max_ev, which clamp it.
//
// Method:
// 1. Metering (m1 -> m2, shaders/effects/auto_exposure/auto_exposure_meter.wgsl), the log-average: per pixel
//    e = clamp(log2(Y / 0.18), min_ev, max_ev) with Y the Rec. 709 luminance of the
//    linear input (at least 1e-10: black counts as min_ev, so letterbox bars or a
//    black frame cannot drive the exposure to infinity; a few very bright pixels
//    count as max_ev). Two reduction passes, each texel the exact (mean, count)
//    of the texels it covers: m1 at 1/8 of the input (8 x 8 pixel blocks), m2
//    1 x 1: the mean of e over every pixel. Under compute execution both are
//    compute passes, 64 invocations per output texel summing in a tree in
//    workgroup memory; under fragment execution (lavapipe), fragment passes
//    (m1 keeps many output tiles, which lavapipe shades on all its threads).
// 2. Adaptation (adapt, 1 x 1, shaders/effects/auto_exposure/auto_exposure_adapt.wgsl, fed back: PASS.adapt[-1]):
//    target = clamp(metered mean, min_ev, max_ev); dt = this frame's time minus the
//    last one's (the standard value `time`, frame / fps). The EV moves towards the
//    target by at most speed_up * dt EV per frame when it rises (the scene got
//    brighter) and speed_down * dt when it falls: linear in EV, so it reaches the
//    target exactly. The first frame of a sequence, a still image, or a frame whose
//    time did not advance takes the target at once.
// 3. Exposure (out, shaders/effects/auto_exposure/auto_exposure_apply.wgsl): rgb * 2^(compensation - ev), alpha kept.
//
// Parameters:
//   compensation  EV added to the result (default 0: the scene averages 0.18)
//   speed_up      EV per second the exposure follows a brighter scene (default 3)
//   speed_down    EV per second the exposure follows a darker scene (default 1)
//   min_ev        lowest EV (default -10): darker scenes are brightened less
//   max_ev        highest EV (default 10): brighter scenes are darkened less
//
// Passes: m1 (1/8 size), m2 (1 x 1), adapt (1 x 1), out (input
// size, rgba16f). Temporal behaviour: feedback of one 1 x 1 texel; no latency.
EFFECT.auto_exposure = {
    DESCRIPTION = "Automatic exposure: log-average metering by reduction passes, adaptation over time in EV/s, compensation and EV limits.\nOutput: the exposed linear image, for tonemap (fxrun auto_exposure tonemap ...)."
    PARAM = {
        compensation = FLOAT { DEFAULT = 0  RANGE = (-16, 16)  DESCRIPTION = "exposure compensation in EV: the adapted image averages 0.18 * 2^compensation" }
        speed_up = FLOAT { DEFAULT = 3  RANGE = (0, 1000)  DESCRIPTION = "EV per second the exposure follows a scene that got brighter" }
        speed_down = FLOAT { DEFAULT = 1  RANGE = (0, 1000)  DESCRIPTION = "EV per second the exposure follows a scene that got darker" }
        min_ev = FLOAT { DEFAULT = -10  RANGE = (-64, 64)  DESCRIPTION = "lowest exposure value, EV relative to a scene averaging 0.18 (darker scenes are brightened less)" }
        max_ev = FLOAT { DEFAULT = 10  RANGE = (-64, 64)  DESCRIPTION = "highest exposure value (brighter scenes are darkened less)" }
    }
    PASS = {
        m1 = SHADER.auto_exposure_meter {
            img = IN
            min_ev = PARAM.min_ev
            max_ev = PARAM.max_ev
            DEFINE.FIRST = 1
            OUT.SCALE = 0.125
            OUT.FORMAT = rg32f
        }
        m2 = SHADER.auto_exposure_meter { img = PASS.m1  OUT.SIZE = (1, 1)  OUT.FORMAT = rg32f }
        adapt = SHADER.auto_exposure_adapt {
            meter = PASS.m2
            last = PASS.adapt[-1]
            speed_up = PARAM.speed_up
            speed_down = PARAM.speed_down
            min_ev = PARAM.min_ev
            max_ev = PARAM.max_ev
            OUT.SIZE = (1, 1)
            OUT.FORMAT = rgba32f
        }
        out = SHADER.auto_exposure_apply {
            img = IN
            state = PASS.adapt
            compensation = PARAM.compensation
        }
    }
    OUT = out
}
