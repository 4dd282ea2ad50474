// format_convert: numeric colour-format conversions.
//
// What it does
//   Converts the numbers of the image between RGB and Y'CbCr (BT.709 or BT.601,
//   full or limited range) or applies the sRGB transfer curve or its inverse.
//   It is a data converter: its result is stored as it is computed, to be written
//   to a float file (EXR) or, with `fxrun --assume-linear`, to an 8-bit file
//   without any further encoding, or to be read by a following format_convert.
//
// Maths (shaders/effects/format_convert/format_convert.wgsl; K = (Kr, Kb): BT.709 (0.2126, 0.0722),
// BT.601 (0.299, 0.114), Kg = 1 - Kr - Kb)
//   rgb_to_ycbcr:  R'G'B' = sRGB_OETF(RGB) (transfer = srgb) or RGB (transfer = none)
//                  Y' = Kr R' + Kg G' + Kb B'
//                  Pb = (B' - Y') / (2 (1 - Kb)),  Pr = (R' - Y') / (2 (1 - Kr))
//       full:      (Y', Pb + 0.5, Pr + 0.5)                  white -> (1, 0.5, 0.5)
//       limited:   ((16 + 219 Y') / 255, (128 + 224 Pb) / 255, (128 + 224 Pr) / 255)
//                  (the 8-bit video code values divided by 255)
//   ycbcr_to_rgb:  the exact inverse (R' = Y' + 2 (1 - Kr) Pr, B' = Y' + 2 (1 - Kb) Pb,
//                  G' = (Y' - Kr R' - Kb B') / Kg), then sRGB_EOTF with transfer = srgb.
//   linear_to_srgb: v -> 12.92 v (v <= 0.0031308), 1.055 v^(1/2.4) - 0.055 otherwise
//   srgb_to_linear: v -> v / 12.92 (v <= 0.04045), ((v + 0.055) / 1.055)^2.4 otherwise
//   The curves are the exact IEC 61966-2-1 ones, odd-extended to negative values;
//   values above 1 follow the same formula. Alpha is passed through. Y'CbCr is in
//   r, g, b = (Y', Cb, Cr).
//
//   transfer = srgb (default) takes the RGB side as linear light (how fxgraph holds
//   decoded images), so rgb_to_ycbcr of a photo is the usual JPEG/video Y'CbCr of
//   its sRGB-encoded values; transfer = none applies the matrix to the numbers as
//   they are (e.g. with --assume-linear, where the numbers are the file's bytes).
//
// Colour spaces: the pass reads and writes COLORSPACE linear, i.e. the runtime
// neither converts its input nor its output: the numbers are the data. (A pass's
// OUT.COLORSPACE is fixed by the script, not by a parameter, so one effect with a
// direction parameter cannot label linear_to_srgb's output `srgb` and
// srgb_to_linear's `linear` at the same time; labelling the output srgb would also
// make the runtime decode it again before a following pass, undoing the
// conversion, and would put an f16 conversion pass in the Y'CbCr round trip.)
// The output is rgba32f when another pass follows, so a round trip
// RGB -> Y'CbCr -> RGB through two format_convert instances is exact to float
// precision; as the last pass it renders straight into the output.
//
// Parameters: direction, matrix, range, transfer (below).
// Passes: one, `convert`.
EFFECT.format_convert = {
    DESCRIPTION = "Colour-format conversion: RGB <-> Y'CbCr (BT.709/BT.601, full/limited range), linear <-> sRGB.\nA data converter: the numbers are converted and stored as they are (write float files, or use --assume-linear)."
    FORMAT = rgba32f
    PARAM = {
        direction = ENUM { VALUES = (rgb_to_ycbcr, ycbcr_to_rgb, linear_to_srgb, srgb_to_linear)  DEFAULT = rgb_to_ycbcr  DESCRIPTION = "which conversion" }
        matrix = ENUM { VALUES = (bt709, bt601)  DEFAULT = bt709  DESCRIPTION = "Y'CbCr coefficients: BT.709 (HD) or BT.601 (SD, JPEG)" }
        range = ENUM { VALUES = (full, limited)  DEFAULT = full  DESCRIPTION = "Y'CbCr range: full [0, 1] or limited (8-bit 16-235 / 16-240, divided by 255)" }
        transfer = ENUM { VALUES = (srgb, none)  DEFAULT = srgb  DESCRIPTION = "Y'CbCr directions: srgb: RGB is linear light, encoded with the sRGB curve around the matrix; none: the matrix applies to the numbers as they are" }
    }
    PASS = {
        convert = SHADER.format_convert {
            img = IN
            DEFINE.DIRECTION = PARAM.direction
            DEFINE.MATRIX = PARAM.matrix
            DEFINE.RANGE = PARAM.range
            DEFINE.TRANSFER = PARAM.transfer
        }
    }
    OUT = convert
}
