// temporal_denoise: recursive (exponential) temporal average with motion rejection.
//
// Maths (shaders/tdenoise.wgsl), per pixel, with hist = this pass's own output of
// the previous frame (feedback PASS.denoise[-1]) and cur = IN:
//     D   = cur - hist                                  (r, g, b)
//     m   = max(|mean of D over the 3x3 neighbourhood|, |D| / 3), averaged over r, g, b
//     h   = strength * exp(-m^2 / (2 sigma^2))          history weight in [0, strength]
//     out = (1 - h) * cur + h * hist                    (all four channels)
//   Where nothing moves, D is noise: its 3x3 mean is about sigma/3 per channel, h
//   stays near `strength`, and the output is an exponential moving average: for
//   i.i.d. noise of standard deviation s and a constant weight h, the output noise
//   tends to s * sqrt((1 - h) / (1 + h)) (0.23 s for h = 0.9). Where the image
//   changes by several sigma (motion, cuts), m is large, h falls to about 0 and the
//   output follows the current frame at once (no ghosting). The 3x3 mean makes the
//   motion test robust to the noise itself; the |D| / 3 term still catches changes
//   of single pixels.
//   First output (frame 0; the history is zero before it): out = cur.
//
// Parameters:
//   strength  history weight where nothing moves (0 .. 0.99, default 0.9; 0 = off)
//   sigma     noise level in linear units (default 0.05): differences of a few sigma
//             count as motion. Set it near the standard deviation of the noise.
//
// Passes: one, `denoise` (SHADER.tdenoise: cur = IN, hist = PASS.denoise[-1]), at
// the input's size in rgba16f (the history keeps half-float precision; the output
// is converted to the requested format).
//
// Temporal behaviour: feedback only (no latency, no input history). A stream that
// starts mid-sequence starts afresh (its first output is its first input). At rate 2
// the history is the previous output (the previous field).
EFFECT.temporal_denoise = {
    DESCRIPTION = "Temporal denoise: recursive average of the frames, with motion rejection.\nout = cur + h (history - cur), h = strength * exp(-m^2 / 2 sigma^2), m = local difference to the history."
    PARAM = {
        strength = FLOAT { DEFAULT = 0.9  RANGE = (0, 0.99)  DESCRIPTION = "history weight where nothing moves (0: off)" }
        sigma = FLOAT { DEFAULT = 0.05  RANGE = (0.0001, 10)  DESCRIPTION = "noise level (linear units); differences of a few sigma count as motion" }
    }
    PASS = {
        denoise = SHADER.tdenoise {
            cur = IN
            hist = PASS.denoise[-1]
            strength = PARAM.strength
            sigma = PARAM.sigma
        }
    }
    OUT = denoise
}
