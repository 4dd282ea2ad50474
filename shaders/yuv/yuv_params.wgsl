// The parameters of a Y'CbCr plane layout, shared by yuv_to_rgb.wgsl and
// rgb_to_yuv.wgsl (src/gpu/yuv/: `Params`, the same order).
struct Params {
    width: u32,
    height: u32,
    // 0 x 0 for luma-only (mono) frames.
    chroma_width: u32,
    chroma_height: u32,
    // Bytes per sample: 1 (8 bits) or 2 (9 to 16 bits, little-endian).
    bytes: u32,
    // Horizontal chroma siting: 0 full (4:4:4), 1 between columns, 2 co-sited.
    h_siting: u32,
    // 1: the per-field taps (the second half of the tap table).
    fields: u32,
    // 1: R'G'B' clipped to [0, 1] (the default); 0: extended past it.
    clip: u32,
    // The RGB side: 0 sRGB-encoded 8-bit codes, 1 linear rgba16f, 2 linear rgba32f.
    rgb: u32,
    // To RGB: u32 words per texel row (rows padded for the texture copy).
    row_words: u32,
    // To planes: u32 words of the frame, and invocations per dispatch row.
    words: u32,
    groups_x: u32,
    // Luma code of black and codes per unit; chroma code of zero and codes per unit.
    y_off: f32,
    y_scale: f32,
    c_mid: f32,
    c_scale: f32,
    max_code: f32,
    kr: f32,
    kg: f32,
    kb: f32,
    // R' = Y' + rv Pr; G' = Y' + gu Pb + gv Pr; B' = Y' + bu Pb.
    rv: f32,
    gu: f32,
    gv: f32,
    bu: f32,
};
