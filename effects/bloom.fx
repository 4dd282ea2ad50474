// bloom: light bleeding around bright areas (HDR bloom with a mip chain).
//
// A soft threshold keeps what is brighter than `threshold`; that is blurred by a
// chain of five downsamples (1/2 .. 1/32 of the input) and upsamples back, each
// upsample mixing the coarser level into the finer one with weight `radius`; the
// result is added to the input times `intensity`:
//
//   down_1 = soft_threshold(box4x4(IN))                                   1/2
//   down_k = filter13(down_{k-1}),  k = 2..5                              1/4 .. 1/32
//   up_4   = mix(down_4, tent(down_5), radius)                            1/16
//   up_k   = mix(down_k, tent(up_{k+1}), radius),  k = 3..1               1/8 .. 1/2
//   out    = IN + intensity * box(up_1)                                   full size
//
// filter13: the 13-tap downsample of Jimenez (SIGGRAPH 2014, Call of Duty: AW);
// box4x4: 4 bilinear taps (the first level reads the full-size input, so it takes
// the cheaper filter); tent: 3x3 tent upsample; box: 4 bilinear taps at half a
// texel (see shaders/effects/bloom/bloom_down.wgsl and shaders/effects/bloom/bloom_up.wgsl).
// The level weights (1 - radius), radius (1 - radius), ..., radius^4 sum to 1, so the
// bloom carries the thresholded light's energy, scaled by `intensity`.
// soft_threshold: brightness b = max(r, g, b), colour scaled by contribution(b) / b,
// contribution = max(b - threshold, clamp(b - threshold + knee, 0, 2 knee)^2 / (4 knee)).
// Intermediate levels are rgba16f (HDR range); alpha is the input's.
//
// Parameters:
//   threshold  brightness (linear) where bloom starts (default 1; 8-bit photos
//              reach at most 1, so their highlights bloom through the knee)
//   knee       half-width of the soft transition around the threshold (default 0.5)
//   intensity  strength of the added bloom (default 0.5; 0 = identity)
//   radius     0..1, weight of the coarser levels: larger spreads wider (default 0.7)
//
// Passes: down1 (prefilter, 1/2), down2..down5 (1/4 .. 1/32), up4..up1, final
// (input size); each level is half of the previous one (rounded, at least 1 px).
EFFECT.bloom = {
    DESCRIPTION = "HDR bloom: soft-thresholded highlights blurred by a 5-level mip chain and added back.\nDownsample: 13-tap filter (Jimenez 2014, 4x4 box on the first level); upsample: 3x3 tent; energy-preserving level mix.\nThreshold 1 blooms only light brighter than white (HDR input): on an 8-bit photo little changes; lower it (threshold = 0.5) for one."
    FORMAT = rgba16f
    PARAM = {
        threshold = FLOAT { DEFAULT = 1  RANGE = (0, 65000)  DESCRIPTION = "brightness (max of r, g, b, linear) where bloom starts" }
        knee = FLOAT { DEFAULT = 0.5  RANGE = (0, 1000)  DESCRIPTION = "half-width of the soft transition around the threshold" }
        intensity = FLOAT { DEFAULT = 0.5  RANGE = (0, 100)  DESCRIPTION = "strength of the added bloom; 0 leaves the image unchanged" }
        radius = FLOAT { DEFAULT = 0.7  RANGE = (0, 1)  DESCRIPTION = "weight of the coarser levels: larger spreads the light wider" }
    }
    PASS = {
        down1 = SHADER.bloom_down {
            img = IN
            threshold = PARAM.threshold
            knee = PARAM.knee
            DEFINE.PREFILTER = 1
            DEFINE.TAPS = 4
            OUT.SCALE = (0.5, 0.5)
        }
        down2 = SHADER.bloom_down {
            img = PASS.down1
            OUT.SCALE = (0.5, 0.5)
            OUT.RELATIVE_TO = img
        }
        down3 = SHADER.bloom_down {
            img = PASS.down2
            OUT.SCALE = (0.5, 0.5)
            OUT.RELATIVE_TO = img
        }
        down4 = SHADER.bloom_down {
            img = PASS.down3
            OUT.SCALE = (0.5, 0.5)
            OUT.RELATIVE_TO = img
        }
        down5 = SHADER.bloom_down {
            img = PASS.down4
            OUT.SCALE = (0.5, 0.5)
            OUT.RELATIVE_TO = img
        }
        up4 = SHADER.bloom_up {
            base = PASS.down4
            low = PASS.down5
            radius = PARAM.radius
            OUT.SCALE = (1, 1)
            OUT.RELATIVE_TO = base
        }
        up3 = SHADER.bloom_up {
            base = PASS.down3
            low = PASS.up4
            radius = PARAM.radius
            OUT.SCALE = (1, 1)
            OUT.RELATIVE_TO = base
        }
        up2 = SHADER.bloom_up {
            base = PASS.down2
            low = PASS.up3
            radius = PARAM.radius
            OUT.SCALE = (1, 1)
            OUT.RELATIVE_TO = base
        }
        up1 = SHADER.bloom_up {
            base = PASS.down1
            low = PASS.up2
            radius = PARAM.radius
            OUT.SCALE = (1, 1)
            OUT.RELATIVE_TO = base
        }
        final = SHADER.bloom_up {
            base = IN
            low = PASS.up1
            intensity = PARAM.intensity
            DEFINE.FINAL = 1
        }
    }
    OUT = final
}
