// temporal_denoise: motion-compensated recursive temporal denoiser (header: TODO)
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
        nres = SHADER.tdn_noise_res { img = IN  OUT.SCALE = 0.25  OUT.FORMAT = rg16f }
        nblk = SHADER.tdn_noise_blk { img = PASS.nres  OUT.SCALE = 0.25  OUT.RELATIVE_TO = img  OUT.FORMAT = rg16f }
        nsig = SHADER.tdn_noise_est {
            blk = PASS.nblk
            last = PASS.nsig[-1]
            sigma = PARAM.sigma
            OUT.SIZE = (1, 1)
            OUT.FORMAT = r32f
        }
        y1 = SHADER.tdn_luma { img = IN  DEFINE.LUMA = 1  OUT.SCALE = 0.5  OUT.FORMAT = r16f }
        y2 = SHADER.tdn_luma { img = PASS.y1  OUT.SCALE = 0.5  OUT.RELATIVE_TO = img  OUT.FORMAT = r16f }
        y3 = SHADER.tdn_luma { img = PASS.y2  OUT.SCALE = 0.5  OUT.RELATIVE_TO = img  OUT.FORMAT = r16f }
        mv3 = SHADER.tdn_match {
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
        mv2 = SHADER.tdn_match {
            cur = PASS.y2
            prev = PASS.y2[-1]
            last = PASS.mv2[-1]
            coarse = PASS.mv3
            DEFINE.WINDOW = 4
            OUT.SCALE = 0.5
            OUT.RELATIVE_TO = cur
            OUT.FORMAT = rg32f
        }
        mv1 = SHADER.tdn_match {
            cur = PASS.y1
            prev = PASS.y1[-1]
            last = PASS.mv1[-1]
            coarse = PASS.mv2
            DEFINE.WINDOW = 6
            OUT.SCALE = 0.25
            OUT.RELATIVE_TO = cur
            OUT.FORMAT = rg32f
        }
        mv0 = SHADER.tdn_refine {
            cur = IN
            hist = PASS.acc[-1]
            coarse = PASS.mv1
            OUT.SCALE = 0.125
            OUT.FORMAT = rg32f
        }
        warp = SHADER.tdn_warp { hist = PASS.acc[-1]  mv = PASS.mv0  OUT.FORMAT = rgba16f }
        acc = SHADER.tdn_blend {
            cur = IN
            warped = PASS.warp
            sig = PASS.nsig
            frames = PARAM.frames
            threshold = PARAM.threshold
            OUT.FORMAT = rgba16f
        }
        out = SHADER.tdn_out {
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
