// taa: temporal anti-aliasing. Frames rendered with a different sub-pixel jitter
// each are accumulated along the motion vectors into a history that converges to
// the pixel-area average (an anti-aliased image), while moving and newly visible
// content falls back on the current frame.
//
// Inputs: IN, the frame in linear light (HDR: run taa before tonemap);
// AUX.motion, the motion vectors in pixels (current minus previous position, x
// right, y down; a pixel at p was at p - motion one frame earlier; without the
// jitter); AUX.depth, linear view depth (larger is farther). The effect declares
// `JITTER = halton23`: a frame source that renders its frames (the renderer)
// offsets frame n by `halton23(n)` (src/script/jitter.rs) and gives the offset as
// the standard value `jitter` (pixels from the pixel centre, x right, y down). A
// sequence without jitter (the value 0) is still filtered: the history then
// converges to the aliased image, and only flicker and crawling are reduced.
//
// Method, per pixel p (one frame):
// 1. Reprojection data (geo, shaders/effects/taa/taa_geometry.wgsl): the nearest depth of the
//    3x3 neighbourhood and the motion vector of that nearest pixel (the
//    foreground's motion dilated by one pixel over its silhouette: edge pixels
//    follow the object). Kept one frame (PASS.geo[-1]) for the disocclusion test.
// 2. The history lives at 3x the input's size per axis (HISTORY_SCALE in
//    shaders/effects/taa/taa_resolve.wgsl): a texel covers a ninth of a pixel.
//    Each jittered sample, taken at q + 0.5 + jitter (input pixels), goes into
//    the texels around it with the weight exp(-d^2 / (2 filter_width^2)), d its
//    distance from the texel's centre: over the jitter sequence a texel collects
//    the samples that fell near it, and the output, the mean of a pixel's 3x3
//    texels, converges to the pixel-area (box) average of the scene.
// 3. History: the state of the previous frame at x - motion (x the texel's
//    centre, motion of step 1 at its pixel), resampled with Keys' cubic, a =
//    -0.75 (9 bilinear taps) for rgb and bilinearly for the weight. Each
//    resampling at a fractional position softens the history a little, and the
//    softening builds up with its length; at a third of a pixel it is a ninth of
//    what it would be at the input's resolution (this is why the history is
//    larger than the frame: tests/taa_scene.rs measures 0.80 of the
//    un-anti-aliased error at 1x, 0.62 at 2x, 0.58 at 3x). With f the fraction
//    of the reprojected position (texels) and s = fx (1 - fx) + fy (1 - fy) (0
//    for whole-texel motion, at most 0.5), the history stands for at most
//    resample_limit / s frames.
//    The history is dropped everywhere on the first frame after a camera cut
//    (the standard value `cut`: the previous frame shows another shot), and per
//    texel when x - motion is outside the frame (content entering at an edge),
//    or when the data stored there one frame earlier shows another surface: its
//    nearest depth differs by more than depth_tolerance times the current one,
//    or its motion by more than motion_tolerance pixels (disocclusion: the
//    background a moving object uncovers).
// 4. Clipping: in YCoCg, the history is clipped towards the centre of the box
//    mean +- clip_gamma * sigma of the 3x3 current samples around the texel
//    (variance clipping, Salvi 2016), intersected with their min/max and
//    extended to hold the current estimate, so stale colours (ghosts, lighting
//    changes) cannot survive.
// 5. Accumulate: the state holds rgb = the weighted mean and a = w, the sum of
//    the weights it stands for. w_new = min(w_prev, (frames - 1) w1) + this
//    frame's weights, w1 = 2 pi filter_width^2 the weight one frame brings on
//    average: the current frame weighs at least 1 / frames. Where no sample is
//    near and the history is gone, a wider Gaussian of the 3x3 samples (sigma
//    1/3 px) stands in. NaN becomes 0 and values are kept within the rgba16f
//    range, so a bad input pixel cannot stay in the history.
// 6. Output (out): the mean of the pixel's 3x3 state texels, with the current
//    frame's alpha.
//
// Cost: the state is 9 times a frame (rgba16f; at 1920x1080 two of 5760x3240,
// 149 MB each), and the resolve runs once per texel: on lavapipe (a CPU) at
// 960x540 the resolve took 860-1190 ms a frame against 80-107 ms with the
// history at the frame's size (the room under the orbit camera, same run); on a
// GPU the pass is bound by its loads and stays small against a frame.
//
// Everything is linear light (no tone mapping inside): run it before tonemap.
//
// Parameters:
//   frames            most frames the history stands for (default 10: the current
//                     frame weighs at least 0.1; higher: smoother, more blur in motion)
//   clip_gamma        clipping box half-width in standard deviations (default 1.25;
//                     lower: less ghosting, more flicker)
//   filter_width      the samples' Gaussian, sigma in input pixels (default 0.13;
//                     smaller: sharper, slower to converge)
//   resample_limit    history length in sub-texel motion, resample_limit / s frames
//                     (default 1: 2 to 4 frames at half-texel fractions; higher:
//                     less aliasing and more blur in motion)
//   depth_tolerance   relative nearest-depth change that counts as a disocclusion (0.1)
//   motion_tolerance  motion change in pixels that counts as a disocclusion (2)
//   view              taa (default) | history (n / frames as grey, for inspection)
//
// Passes: geo (rgba16f), resolve (rgba16f, fed back, 3x the input's size per
// axis), out; geo and out at the input's size.
// Temporal behaviour: feedback only (PASS.resolve[-1], PASS.geo[-1]); no latency.
// The first frame is the current frame unjittered; the history builds up over
// about `frames` frames.
EFFECT.taa = {
    DESCRIPTION = "Temporal anti-aliasing: jittered frames accumulated along AUX.motion into a history at 3x the frame's resolution, with disocclusion tests (AUX.depth) and YCoCg variance clipping.\nDeclares JITTER = halton23: the renderer jitters its frames; linear HDR, run it before tonemap."
    JITTER = halton23
    PARAM = {
        frames = FLOAT { DEFAULT = 10  RANGE = (1, 64)  DESCRIPTION = "most frames the history stands for: the current frame weighs at least 1 / frames" }
        clip_gamma = FLOAT { DEFAULT = 1.25  RANGE = (0.25, 8)  DESCRIPTION = "history clipping box half-width, in standard deviations of the 3x3 neighbourhood (lower: less ghosting, more flicker)" }
        filter_width = FLOAT { DEFAULT = 0.13  RANGE = (0.05, 2)  DESCRIPTION = "sigma in input pixels of the Gaussian that weighs each jittered sample into the history texels (a third of a pixel) around it" }
        resample_limit = FLOAT { DEFAULT = 1  RANGE = (0.01, 1000)  DESCRIPTION = "in sub-texel motion the history stands for at most resample_limit / s frames, s = fx (1 - fx) + fy (1 - fy) of the reprojection's fraction in history texels (less blur builds up; 1000: no limit)" }
        depth_tolerance = FLOAT { DEFAULT = 0.1  RANGE = (0, 10)  DESCRIPTION = "relative change of the nearest depth beyond which the reprojected history is a disocclusion" }
        motion_tolerance = FLOAT { DEFAULT = 2  RANGE = (0, 1000)  DESCRIPTION = "change of the motion vector, in pixels, beyond which the reprojected history is a disocclusion" }
        view = ENUM { VALUES = (taa, history)  DEFAULT = taa  DESCRIPTION = "output: the anti-aliased image, or for inspection the history length n / frames as grey" }
    }
    PASS = {
        geo = SHADER.taa_geometry {
            depth = AUX.depth
            motion = AUX.motion
            OUT.FORMAT = rgba16f
        }
        resolve = SHADER.taa_resolve {
            cur = IN
            hist = PASS.resolve[-1]
            geo = PASS.geo
            geo_prev = PASS.geo[-1]
            frames = PARAM.frames
            clip_gamma = PARAM.clip_gamma
            filter_width = PARAM.filter_width
            resample_limit = PARAM.resample_limit
            depth_tolerance = PARAM.depth_tolerance
            motion_tolerance = PARAM.motion_tolerance
            OUT.FORMAT = rgba16f
            OUT.SCALE = 3
        }
        out = SHADER.taa_out {
            state = PASS.resolve
            cur = IN
            frames = PARAM.frames
            filter_width = PARAM.filter_width
            DEFINE.VIEW = PARAM.view
        }
    }
    OUT = out
}
