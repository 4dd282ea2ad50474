// frame_blend: weighted average of the last N frames (like ffmpeg's tmix).
//
// Maths (shaders/effects/frame_blend/frame_blend.wgsl), per pixel and channel (alpha too):
//     out(t) = k * sum_{i=0}^{N-1} w_i * IN(max(t - i, 0))
//     k      = scale, or 1 / sum_{i<N} w_i when scale = 0 (the default: a weighted
//              mean; if the weights sum to 0, k = 1)
//   N = frames (1 .. 8). The weights are newest first: w_0 is the current frame,
//   w_1 the previous one, ... : (w_0, w_1, w_2, w_3) = weights,
//   (w_4, .., w_7) = weights_more. Defaults: all 1, N = 3, i.e. the plain mean of
//   the current and two previous frames. Negative weights are allowed (with
//   scale = 1, weights = (-1, 2, -1, 0) is a temporal second difference).
//   At the start of a sequence the earlier frames clamp to frame 0 (the docs'
//   rule for IN[-n]), so out(0) = frame 0, and out(1) with N = 3 and equal weights
//   is (f1 + 2 f0) / 3. Looking back only, the effect has no latency and nothing
//   special at the end.
//
// Parameters: frames, weights, weights_more, scale (below).
//
// Passes: one, `mix` (SHADER.frame_blend with f0 = IN, f1 = IN[-1], .., f7 = IN[-7]) at the
// input's size in rgba16f. The script binds all 8 frames whatever N is (the
// runtime keeps 7 earlier input frames); only the first N are read (FRAMES define).
EFFECT.frame_blend = {
    DESCRIPTION = "Frame blend: weighted mean of the current and up to 7 earlier frames (like ffmpeg tmix).\nweights are newest first; scale = 0 divides by the sum of the weights."
    PARAM = {
        frames = INT { DEFAULT = 3  RANGE = (1, 8)  DESCRIPTION = "number of frames mixed: the current one and frames - 1 earlier ones" }
        weights = VEC4 { DEFAULT = (1, 1, 1, 1)  RANGE = (-16, 16)  DESCRIPTION = "weights of the current frame and the 3 previous ones" }
        weights_more = VEC4 { DEFAULT = (1, 1, 1, 1)  RANGE = (-16, 16)  DESCRIPTION = "weights of the frames 4 to 7 back" }
        scale = FLOAT { DEFAULT = 0  RANGE = (0, 32767)  DESCRIPTION = "factor of the weighted sum; 0: divide by the sum of the weights" }
    }
    PASS = {
        mix = SHADER.frame_blend {
            f0 = IN
            f1 = IN[-1]
            f2 = IN[-2]
            f3 = IN[-3]
            f4 = IN[-4]
            f5 = IN[-5]
            f6 = IN[-6]
            f7 = IN[-7]
            weights = PARAM.weights
            weights_more = PARAM.weights_more
            scale = PARAM.scale
            DEFINE.FRAMES = PARAM.frames
        }
    }
    OUT = mix
}
