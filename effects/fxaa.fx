// fxaa: fast approximate anti-aliasing (FXAA 3.11 "quality" style).
//
// What it does
//   Smooths jagged (aliased) edges of a rendered or upscaled image in one pass, by
//   finding the edge through each high-contrast pixel and resampling the pixel a
//   fraction of a texel across the edge. Flat and low-contrast pixels are left
//   exactly as they are.
//
// Algorithm (shaders/effects/fxaa/fxaa.wgsl), after T. Lottes' published FXAA 3.11 description
//   luma L = Rec.709 weighted sum of the sRGB-encoded colour (perceptual, as FXAA
//   computes it on gamma-encoded frames), read through a second binding of IN
//   with COLORSPACE = srgb: free for 8-bit inputs (raw view of the same texture);
//   a float input gets one conversion pass for it.
//   1. Contrast: with the 4-neighbourhood N, S, E, W of the centre M,
//      range = max - min; if range < max(absolute_threshold, contrast_threshold * max)
//      the pixel is returned unchanged.
//   2. Sub-pixel amount: a = |(2 (N+S+E+W) + NW+NE+SW+SE) / 12 - M| / range,
//      sub = subpix * smoothstep(a)^2 (isolated pixels, thin lines).
//   3. Orientation: sums of absolute second differences along rows vs. columns of
//      the 3x3 (centre row/column weighted 2) say whether the edge is horizontal or
//      vertical; the side is the neighbour across it with the larger gradient.
//   4. End search: from the point half a texel towards that neighbour, step along
//      the edge both ways (1, 1.5, 2, 4, 12 texels: FXAA's default preset; taps average
//      the two pixels across the edge) until the luma departs from the pair's mean
//      by a quarter of the gradient: the ends of the staircase step.
//   5. Offset: 0.5 - (distance to the nearer end) / (span length), used only when
//      the luma at that end turns away from the centre's side (otherwise 0);
//      offset = max(that, sub). The colour is resampled bilinearly `offset` texels
//      across the edge (linear light, alpha included); an offset below 1/256
//      texel keeps the pixel exactly (a straight edge with subpix = 0).
//   The result is a convex combination of input pixels: it stays within the
//   input's range.
//
// Parameters: contrast_threshold, absolute_threshold, subpix (below); defaults are
// FXAA's "high quality" settings.
// Passes: one, `fxaa`; output in the input's format (8-bit stays 8-bit).
// Cost: 9 luma loads per pixel; the search (at most 2 x 5 bilinear taps) and the
// resampling only where the contrast test passes (a few % of a photo's pixels).
EFFECT.fxaa = {
    DESCRIPTION = "FXAA anti-aliasing (3.11 quality style): edge search and sub-pixel blend, one pass.\nPixels below the contrast threshold are unchanged."
    FORMAT = IN
    PARAM = {
        contrast_threshold = FLOAT { DEFAULT = 0.125  RANGE = (0.01, 1)  DESCRIPTION = "minimum local contrast, relative to the brightest neighbour, for a pixel to be processed (0.063: overkill, 0.333: too little)" }
        absolute_threshold = FLOAT { DEFAULT = 0.0312  RANGE = (0, 1)  DESCRIPTION = "minimum local contrast in luma units (skips dark noise)" }
        subpix = FLOAT { DEFAULT = 0.75  RANGE = (0, 1)  DESCRIPTION = "amount of sub-pixel aliasing removal (0: edges only, 1: softer)" }
    }
    PASS = {
        fxaa = SHADER.fxaa {
            img = IN
            enc = IN
            enc.COLORSPACE = srgb
            contrast_threshold = PARAM.contrast_threshold
            absolute_threshold = PARAM.absolute_threshold
            subpix = PARAM.subpix
        }
    }
    OUT = fxaa
}
