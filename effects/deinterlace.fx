// deinterlace: turns interlaced frames (two fields woven together) into progressive
// frames, at frame rate or at field rate.
//
// Fields
//   Rows y = 0, 2, 4, ... are the top field, rows 1, 3, 5, ... the bottom field. The
//   two fields of a frame were captured half a frame apart: with field_order = tff
//   the top field first (frame k: top at field time 2k, bottom at 2k + 1), with bff
//   the bottom field first.
//
// Output rate
//   At rate 1 (the default; one output per frame) the first field in time is kept
//   and the other one is reconstructed. At rate 2 (a stream with `rate = 2`, the
//   CLI's `--rate 2`) every frame gives two outputs, one per field, in time order:
//   the standard value `subframe` is 0 for the first field, 1 for the second. The
//   kept field's parity is p = field_order XOR subframe (tff = 0, bff = 1); its rows
//   are copied exactly (bob, adaptive) and the rows of the other parity, the
//   "missing" rows, are reconstructed.
//
// Modes (shaders/effects/deinterlace/deinterlace.wgsl, DEFINE.MODE)
//   bob       missing row y = (cur[y-1] + cur[y+1]) / 2: line doubling of the kept
//             field with linear vertical interpolation. Never combs, halves the
//             vertical resolution everywhere.
//   blend     every row y = (cur[y-1] + 2 cur[y] + cur[y+1]) / 4: a vertical [1 2 1]
//             blur of the woven frame, i.e. the average of the two fields (each
//             output row is half one field, half the other). No combing, moving
//             objects show both field positions (ghosting). Both subframes of a
//             frame give the same image.
//   adaptive  in the spirit of yadif / bwdif (written from their published
//             description): for a missing row y, per channel, with
//               c = cur[y-1], e = cur[y+1]  (kept rows above and below, output time)
//               a, b = the missing row in the two fields of that parity nearest in
//                      time: (IN[-1], IN) when the first field is kept, (IN, IN[+1])
//                      when the second is
//               d = (a + b) / 2                           temporal prediction
//               motion = max(|a - b| / 2,
//                            (|IN[-1][y-1] - c| + |IN[-1][y+1] - e|) / 2,
//                            (|IN[+1][y-1] - c| + |IN[+1][y+1] - e|) / 2)
//             If motion <= threshold (still), the output is d: in still areas the
//             missing row is the real row of the other field, so the image keeps its
//             full vertical resolution (exactly, for identical frames). Otherwise an
//             interpolation i, clamped to [d - m, d + m]:
//               i = 0.6197 (c + e) - 0.1197 (cur[y-3] + cur[y+3])   (4-tap vertical,
//                   the w3fdif / bwdif spatial filter), or, where |c - e| > |a - b|
//                   (vertical contrast beyond the temporal change),
//               i = 0.5260 (c + e) - 0.0260 (cur[y-3] + cur[y+3]) + (d - (B + F) / 2) / 6
//                   (a softer 4-tap plus the vertical high frequencies of the
//                   temporal prediction),
//             where B = temporal prediction of row y-2, F = of row y+2, and m is the
//             motion widened by the spatial-temporal check
//               m = max(motion, min(d-e, d-c, max(B-c, F-e)), -max(d-e, d-c, min(B-c, F-e)))
//             so a temporal prediction that sticks out of its vertical neighbours
//             (combing) is not trusted, while slow motion keeps temporal detail.
//             The first output of a sequence (frame 0, subframe 0) has no earlier
//             field: there a, b = (IN, IN[+1]) serve the still test only, and moving
//             pixels get the 4-tap vertical interpolation unclamped.
//
// Rows outside the image are replaced by the nearest row of the same parity; columns
// clamp. IN[-1] and IN[+1] clamp at the ends of the sequence. The effect reads
// IN[+1], so output t is produced when input t + 1 has arrived (latency 1), in every
// mode. A single image is a one-frame sequence (IN[-1] = IN[+1] = IN): bob and blend
// work as on any frame, but adaptive sees no motion and returns the woven image
// unchanged; use bob for stills.
//
// Values: every mode works per channel (alpha too) on the values as the input
// stores them (COLORSPACE = stored). For an 8-bit input these are the sRGB-encoded
// codes, like yadif / bwdif on 8-bit video (the interpolation weights and the motion
// threshold are meant for perceptually even steps): the passes read and write the
// raw 8-bit values, no decode or encode per texel, and the output file gets them
// unchanged. A float input (EXR, 16-bit, HDR) is deinterlaced in linear light as
// stored, with no conversion: kept rows are exact, values above 1 and below 0
// survive; the 4-tap interpolation is kept from ringing below zero next to
// non-negative neighbours.
//
// Parameters: mode, field_order, threshold (below).
// Passes: `rows` (SHADER.deinterlace STAGE 0 with IN, IN[-1], IN[+1]) reconstructs the
// missing rows at half height (rgba16f); `deint` (STAGE 1) weaves them with the kept
// rows at the input's size (rgba32f; written straight into an 8-bit output).
EFFECT.deinterlace = {
    DESCRIPTION = "Deinterlace: bob, blend or motion-adaptive (yadif/bwdif-like) field reconstruction.\nField-rate output at rate 2 (subframe 0/1 = first/second field); at rate 1 the first field is kept."
    PARAM = {
        mode = ENUM { VALUES = (bob, blend, adaptive)  DEFAULT = adaptive  DESCRIPTION = "bob: line doubling; blend: average of the fields; adaptive: temporal where still, vertical 4-tap interpolation clamped around it where moving" }
        field_order = ENUM { VALUES = (tff, bff)  DEFAULT = tff  DESCRIPTION = "which field was captured first: top (even rows) or bottom (odd rows)" }
        threshold = FLOAT { DEFAULT = 0  RANGE = (0, 1)  DESCRIPTION = "adaptive: temporal difference (0..1, in the stored values: sRGB-encoded for 8-bit inputs) at or below which a pixel counts as still" }
    }
    PASS = {
        // The missing rows only, at half height (row r is image row 2r + 1 - p;
        // round(h / 2) rows, enough for either parity).
        rows = SHADER.deinterlace {
            cur = IN
            prev = IN[-1]
            next = IN[+1]
            cur.COLORSPACE = stored
            prev.COLORSPACE = stored
            next.COLORSPACE = stored
            cur.FILTER = nearest
            field_order = PARAM.field_order
            threshold = PARAM.threshold
            DEFINE.MODE = PARAM.mode
            DEFINE.STAGE = 0
            OUT.SCALE = (1, 0.5)
            OUT.FORMAT = rgba16f
            OUT.COLORSPACE = stored
        }
        // Full size: the kept rows from IN, the missing rows from `rows` (blend
        // computes every row here).
        deint = SHADER.deinterlace {
            cur = IN
            missing = PASS.rows
            cur.COLORSPACE = stored
            missing.COLORSPACE = stored
            cur.FILTER = nearest
            OUT.FORMAT = rgba32f
            OUT.COLORSPACE = stored
            field_order = PARAM.field_order
            DEFINE.MODE = PARAM.mode
            DEFINE.STAGE = 1
        }
    }
    OUT = deint
}
