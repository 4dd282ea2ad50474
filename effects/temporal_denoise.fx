// temporal_denoise: motion-compensated recursive temporal denoiser with a spatial
// fallback and an automatic noise estimate.
//
// Values: the effect works on sRGB code values (COLORSPACE = srgb: an 8-bit input is
// read without decoding, a linear input is encoded first), where the noise of
// cameras and of 8-bit files is much closer to uniform than in linear light.
// `sigma` and all the thresholds are in these units (0..1; 8-bit value / 255).
//
// State: the pass `acc` (rgba16f) holds, per pixel, rgb = a running mean of the
// frames aligned to the current one and a = n, the number of frames it averages.
// Each frame:
//
// 1. Noise estimate (nres -> nblk -> nsig, sigma = 0): the 3x3 kernel
//    N = (1 -2 1; -2 4 -2; 1 -2 1) cancels smooth content; for white Gaussian noise
//    E|N * I| = 6 sigma sqrt(2/pi). |N * I| (mean of r, g, b) is averaged over
//    16x16-pixel blocks (two 4x reductions); blocks with a pixel within 2/255 of
//    black or white are left out (clipped noise reads low). The 20% quantile of
//    the block means (bisection in a 1x1 pass: one workgroup of 256 lanes counting
//    the blocks of each step together), divided by 6 sqrt(2/pi), is the
//    estimate: the flattest blocks see noise, textured ones read high. It is
//    smoothed over time, sigma_t = mix(sigma_t-1, new, 0.25).
// 2. Motion (y1..y3, mv3..mv0): hierarchical block matching, coarse to fine, on
//    a luma pyramid (r + 2g + b) / 4 at 1/2, 1/4, 1/8 size; the previous frame's
//    levels are the same passes one frame earlier (PASS.y1[-1], ...). One vector
//    per 8x8 pixels, v with cur(x) ~ prev(x + v), cost = mean squared difference
//    over a block (bilinear samples of the previous frame):
//      mv3  1/8 level, 3x3 texels (24 px): exhaustive +-2 texels (+-16 px), plus
//           the previous frame's vector (temporal predictor)
//      mv2  1/4 level, 4x4 texels (16 px): candidates from mv3, the temporal
//           predictor and zero; refined by one-texel steps (two rounds)
//      mv1  1/2 level, 6x6 texels (12 px): the same from mv2
//      mv0  full resolution, 8x8 px, against the filter's own previous output
//           (denoised: far less noise than the previous input): candidates mv1 at
//           the block and its 4 neighbours, then 1/4-pixel steps, then a parabola
//           through the costs around the best (sub-pixel)
//    Each level ends with a parabola fit (sub-texel); zero motion wins near-ties.
//    Per pixel, the field is interpolated bilinearly between the block vectors.
// 3. Warp (warp): the previous state at x + v, Lanczos-3 for rgb (sharp: little
//    blur builds up over the recursion; clamped to the four nearest texels: no
//    overshoot builds up either), n interpolated bilinearly; n = 0 where x + v is outside the frame (new content
//    at the edge has no history).
// 4. Robust blend (acc), with D = cur - warped per channel over the 3x3
//    neighbourhood:
//      r1 = mean over r, g, b of |mean of D| / sigma      a local offset
//      r2 = sqrt(mean of D^2) / sigma                     any local mismatch
//      k  = (1 - smoothstep(0.5, 1.0, r1 / threshold)) (1 - smoothstep(1.2, 1.8, r2 / threshold))
//      n  = 1 + k min(n_prev, frames - 1);   acc = cur + (1 - 1/n) (warped - cur)
//    For a correct match D is noise (r1 ~ 0.3, r2 ~ sqrt(1 + 1/n_prev)) and the
//    state becomes the mean of up to `frames` frames (noise / sqrt(n)); a wrong
//    vector, an occlusion or a cut gives k = 0 and the state restarts from the
//    current frame (no ghost trail, no leak of the previous scene).
// 5. Spatial fallback (out): a 5x5 bilateral filter of the current frame (spatial
//    sigma 1.5 px, range sigma 1.5 sigma) mixed in with weight spatial / n: all of it
//    where there is no history (first frame, cuts, occlusions, the entering edge),
//    little where n is large. Alpha is the input's.
//
// Parameters:
//   sigma      noise standard deviation (code values 0..1); 0 (default) estimates it
//   frames     most frames averaged (default 12; 1 turns the temporal part off)
//   threshold  scales the motion-rejection thresholds (default 1; lower: safer on
//              motion, less denoising; higher: more denoising, risk of ghosts)
//   spatial    weight of the spatial fallback (default 1; 0: none)
//   view       denoised (default) | sigma (the estimate, grey) | history (n /
//              frames, grey) | motion (0.5 + v / 8 px in r, g): for inspection
//
// Temporal behaviour: input history only through the filter's own feedback
// (PASS.x[-1]); no IN[+n], so no latency. The first frame (and a stream that
// starts mid-sequence) is spatially filtered only; the state builds up over about
// `frames` frames. A frame's weight in the state falls by at least
// (frames - 1) / frames per frame: with --frames slices, give --warmup of about
// 6 x frames (72 at the default; see docs/distributed.md).
//
// Cost: 11 passes; the full-resolution ones are nres (4x4 pixels per texel), y1,
// warp, acc and out; the motion search runs on 1/8 as many vectors as pixels.
EFFECT.temporal_denoise = {
    DESCRIPTION = "Temporal denoise: motion-compensated recursive average with a spatial fallback and an automatic noise estimate.\nHierarchical block matching; sigma = 0 estimates the noise level."
    COLORSPACE = srgb
    PARAM = {
        sigma = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "noise standard deviation in sRGB code values (0..1; 8-bit value / 255); 0: estimate it from the input" }
        frames = FLOAT { DEFAULT = 12  RANGE = (1, 64)  DESCRIPTION = "most frames the running mean averages (1: temporal filtering off)" }
        threshold = FLOAT { DEFAULT = 1  RANGE = (0.1, 10)  DESCRIPTION = "motion-rejection threshold in units of sigma: lower rejects more (less ghosting, less denoising)" }
        spatial = FLOAT { DEFAULT = 1  RANGE = (0, 1)  DESCRIPTION = "spatial (bilateral) filtering where the history is short: occlusions, new content, cuts, the first frame" }
        view = ENUM { VALUES = (denoised, sigma, history, motion)  DEFAULT = denoised  DESCRIPTION = "output: the denoised image, or for inspection the noise estimate, n / frames, or the motion vectors" }
    }
    PASS = {
        nres = SHADER.temporal_denoise_noise_residual { img = IN  OUT.SCALE = 0.25  OUT.FORMAT = rg16f }
        nblk = SHADER.temporal_denoise_noise_blocks { img = PASS.nres  OUT.SCALE = 0.25  OUT.RELATIVE_TO = img  OUT.FORMAT = rg16f }
        nsig = SHADER.temporal_denoise_noise_estimate {
            blk = PASS.nblk
            last = PASS.nsig[-1]
            sigma = PARAM.sigma
            OUT.SIZE = (1, 1)
            OUT.FORMAT = r32f
        }
        y1 = SHADER.temporal_denoise_luma { img = IN  DEFINE.LUMA = 1  OUT.SCALE = 0.5  OUT.FORMAT = r16f }
        y2 = SHADER.temporal_denoise_luma { img = PASS.y1  OUT.SCALE = 0.5  OUT.RELATIVE_TO = img  OUT.FORMAT = r16f }
        y3 = SHADER.temporal_denoise_luma { img = PASS.y2  OUT.SCALE = 0.5  OUT.RELATIVE_TO = img  OUT.FORMAT = r16f }
        mv3 = SHADER.temporal_denoise_match {
            cur = PASS.y3
            prev = PASS.y3[-1]
            last = PASS.mv3[-1]
            DEFINE.COARSEST = 1
            DEFINE.WINDOW = 3
            DEFINE.RADIUS = 2
            OUT.SCALE = 1
            OUT.RELATIVE_TO = cur
            OUT.FORMAT = rg32f
        }
        mv2 = SHADER.temporal_denoise_match {
            cur = PASS.y2
            prev = PASS.y2[-1]
            last = PASS.mv2[-1]
            coarse = PASS.mv3
            DEFINE.WINDOW = 4
            OUT.SCALE = 0.5
            OUT.RELATIVE_TO = cur
            OUT.FORMAT = rg32f
        }
        mv1 = SHADER.temporal_denoise_match {
            cur = PASS.y1
            prev = PASS.y1[-1]
            last = PASS.mv1[-1]
            coarse = PASS.mv2
            DEFINE.WINDOW = 6
            OUT.SCALE = 0.25
            OUT.RELATIVE_TO = cur
            OUT.FORMAT = rg32f
        }
        mv0 = SHADER.temporal_denoise_refine {
            cur = IN
            hist = PASS.acc[-1]
            coarse = PASS.mv1
            OUT.SCALE = 0.125
            OUT.FORMAT = rg32f
        }
        warp = SHADER.temporal_denoise_warp { hist = PASS.acc[-1]  mv = PASS.mv0  OUT.FORMAT = rgba16f }
        acc = SHADER.temporal_denoise_blend {
            cur = IN
            warped = PASS.warp
            sig = PASS.nsig
            frames = PARAM.frames
            threshold = PARAM.threshold
            OUT.FORMAT = rgba16f
        }
        out = SHADER.temporal_denoise_out {
            cur = IN
            acc = PASS.acc
            sig = PASS.nsig
            mv = PASS.mv0
            spatial = PARAM.spatial
            frames = PARAM.frames
            DEFINE.VIEW = PARAM.view
            OUT.FORMAT = rgba16f
        }
    }
    OUT = out
}
