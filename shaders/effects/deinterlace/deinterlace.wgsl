// deint: reconstructs one field of an interlaced frame as a progressive image
// (the `deinterlace` effect; the maths is documented in effects/deinterlace.fx).
//
// Rows y = 0, 2, 4, ... are the top field, y = 1, 3, 5, ... the bottom field.
// The kept field has parity p = field_order XOR subframe (tff = 0, bff = 1): the
// first field in time at subframe 0, the second at subframe 1. Its rows are copied;
// the rows of the other parity ("missing" rows) are reconstructed:
//   MODE 0 (bob)       (cur[y-1] + cur[y+1]) / 2
//   MODE 1 (blend)     every row: (cur[y-1] + 2 cur[y] + cur[y+1]) / 4
//   MODE 2 (adaptive)  bwdif-style: a 4-tap vertical interpolation (plus, where the
//                      rows above and below differ more than the field changes in
//                      time, a temporal high-frequency term from the missing
//                      field's neighbours in time), clamped around the temporal
//                      prediction by a motion-dependent margin.
// The values are sRGB-encoded (the script binds every input and output with
// COLORSPACE = srgb: the raw view of an 8-bit texture).
// Rows outside the image are replaced by the nearest row of the same parity,
// columns are clamped.
//
// Two passes (STAGE), so that the costly reconstruction runs on the missing rows
// only (a CPU rasteriser shades 2x2 quads, so a per-row branch in one full-size
// pass runs both sides for every pixel):
//   STAGE 0  `missing`: half height (row r is image row 2r + 1 - p); bob and
//            adaptive reconstruct the missing rows here (blend writes nothing useful)
//   STAGE 1  `weave`: full size; kept rows from cur, missing rows from `missing`
//            (blend computes every row here)
// Every texel is read with a nearest-filter sample at its centre (the adaptive
// mode's 14 reads at constant row offsets from one coordinate, which on lavapipe
// made the pass 10-15 % cheaper than a coordinate per read); the raw 8-bit views
// are much cheaper than sRGB-decoding ones (720x576 `rows` pass, same maths: about
// 10.5 against 19 ms a frame, best of 8 runs).
#define MODE 2
#define STAGE 0

@group(0) @binding(0) var cur: texture_2d<f32>;
#if STAGE == 0
@group(0) @binding(1) var prev: texture_2d<f32>;
@group(0) @binding(2) var next: texture_2d<f32>;
#else
@group(0) @binding(1) var missing: texture_2d<f32>;
#endif
// Nearest, clamp-to-edge; used for every input.
@group(0) @binding(4) var cur_sampler: sampler;

struct Params {
    field_order: u32, // @default(0) @range(0, 1) 0: top field first (tff), 1: bottom field first (bff)
#if STAGE == 0
    threshold: f32,   // @default(0) @range(0, 1) adaptive: temporal difference (0..1 in the stored values: sRGB-encoded for 8-bit inputs) at or below which a pixel is still (the temporal prediction is used as it is)
#endif
    frame: u32,
    subframe: u32,
}
@group(0) @binding(3) var<uniform> params: Params;

// Weights of the adaptive interpolation (the vertical filters of w3fdif / bwdif's
// published description, in units of 1/8192): spatial only, SP0 (c + e) - SP1
// (rows y-3 and y+3); with the temporal high-frequency term, LF0 (c + e) - LF1
// (rows y-3 and y+3) + HF (d - (B + F) / 2). SP and LF sum to 1.
const SP0: f32 = 5077.0 / 8192.0;
const SP1: f32 = 981.0 / 8192.0;
const LF0: f32 = 4309.0 / 8192.0;
const LF1: f32 = 213.0 / 8192.0;
const HF: f32 = 1.0 / 6.0;

// Row y moved into [0, h) keeping its parity (the nearest row of that parity).
fn fold_row(y: i32, h: i32) -> i32 {
    var r = y;
    if (r < 0) {
        r = r & 1;
    } else if (r >= h) {
        r = r - 2 * ((r - h) / 2 + 1);
    }
    return clamp(r, 0, h - 1);
}

// Texture coordinate (v) of the centre of row y (folded).
fn row_v(y: i32, h: i32) -> f32 {
    return (f32(fold_row(y, h)) + 0.5) / f32(h);
}

// The texel of `t` in column u (a texel centre) and row v.
fn at(t: texture_2d<f32>, u: f32, v: f32) -> vec4<f32> {
    return textureSampleLevel(t, cur_sampler, vec2<f32>(u, v), 0.0);
}

#if STAGE == 0
// The missing field's rows before and after the output time are in (prev, cur)
// when the first field is kept (subframe 0), in (cur, next) when the second is.
// The very first output has no earlier field: there the later pair (cur, next) is
// used, for the still test only (moving pixels are interpolated spatially).
fn first_output() -> bool {
    return params.frame == 0u && params.subframe == 0u;
}

// The reconstructed missing row y at column centre u (bob or adaptive).
fn reconstruct(s: vec2<i32>, u: f32, y: i32) -> vec4<f32> {
#if MODE == 0
    return 0.5 * (at(cur, u, row_v(y - 1, s.y)) + at(cur, u, row_v(y + 1, s.y)));
#else
    // All reads by constant row offsets from one coordinate (cheaper on lavapipe
    // than a coordinate per read). Rows past the top or bottom edge clamp there;
    // the selects below replace them by the nearest row of the same parity, which
    // is always one of the texels read (so no read needs a folded coordinate).
    let uv = vec2<f32>(u, (f32(y) + 0.5) / f32(s.y));
    let c_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, -1));
    let e_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, 1));
    var a2u: vec4<f32>;
    var a0: vec4<f32>;
    var a2d: vec4<f32>;
    if (params.subframe == 0u && !first_output()) {
        a2u = textureSampleLevel(prev, cur_sampler, uv, 0.0, vec2<i32>(0, -2));
        a0 = textureSampleLevel(prev, cur_sampler, uv, 0.0);
        a2d = textureSampleLevel(prev, cur_sampler, uv, 0.0, vec2<i32>(0, 2));
    } else {
        a2u = textureSampleLevel(next, cur_sampler, uv, 0.0, vec2<i32>(0, -2));
        a0 = textureSampleLevel(next, cur_sampler, uv, 0.0);
        a2d = textureSampleLevel(next, cur_sampler, uv, 0.0, vec2<i32>(0, 2));
    }
    let b2u_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, -2));
    let b0 = textureSampleLevel(cur, cur_sampler, uv, 0.0);
    let b2d_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, 2));
    let pc_ = textureSampleLevel(prev, cur_sampler, uv, 0.0, vec2<i32>(0, -1));
    let pe_ = textureSampleLevel(prev, cur_sampler, uv, 0.0, vec2<i32>(0, 1));
    let nc_ = textureSampleLevel(next, cur_sampler, uv, 0.0, vec2<i32>(0, -1));
    let ne_ = textureSampleLevel(next, cur_sampler, uv, 0.0, vec2<i32>(0, 1));
    let c3_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, -3));
    let e3_ = textureSampleLevel(cur, cur_sampler, uv, 0.0, vec2<i32>(0, 3));
    // Edges: row -1 is row 1, -2 is 0, -3 is 1; row h is h - 2, h + 1 is h - 1,
    // h + 2 is h - 2 (clamping already gives -2 -> 0 and h + 1 -> h - 1).
    let top = y == 0;
    let bottom = y == s.y - 1;
    let c = select(c_, e_, top);
    let e = select(e_, c_, bottom);
    let pc = select(pc_, pe_, top);
    let pe = select(pe_, pc_, bottom);
    let nc = select(nc_, ne_, top);
    let ne = select(ne_, nc_, bottom);
    let c3 = select(select(c3_, e_, top), c_, y == 2);
    let e3 = select(select(e3_, c_, bottom), e_, y == s.y - 3);
    let a2u_f = select(a2u, a0, y == 1);
    let b2u = select(b2u_, b0, y == 1);
    let a2d_f = select(a2d, a0, y == s.y - 2);
    let b2d = select(b2d_, b0, y == s.y - 2);
    // Temporal prediction and motion: the missing row's change across the output
    // time, and the kept rows' change from the previous and to the next frame.
    let d = 0.5 * (a0 + b0);
    let td0 = abs(a0 - b0);
    let td1 = 0.5 * (abs(pc - c) + abs(pe - e));
    let td2 = 0.5 * (abs(nc - c) + abs(ne - e));
    var diff = max(0.5 * td0, max(td1, td2));
    let still = diff <= vec4<f32>(params.threshold);
    // Spatial-temporal check: widen the margin where the temporal prediction is an
    // extremum against the rows above and below that the field two rows away
    // (predicted the same way) does not confirm.
    let bb = 0.5 * (a2u_f + b2u);
    let ff = 0.5 * (a2d_f + b2d);
    let hi = max(max(d - e, d - c), min(bb - c, ff - e));
    let lo = min(min(d - e, d - c), max(bb - c, ff - e));
    diff = max(diff, max(lo, -hi));
    // Interpolation: 4-tap vertical; where the rows above and below differ more
    // than the missing row changes in time, a softer 4-tap plus the vertical high
    // frequencies of the temporal prediction (d against the mean of the
    // predictions two rows above and below).
    let ce = c + e;
    let ce3 = c3 + e3;
    let sp = SP0 * ce - SP1 * ce3;
    let with_hf = LF0 * ce - LF1 * ce3 + HF * (d - 0.5 * (bb + ff));
    let interp = select(sp, with_hf, abs(c - e) > td0);
    // The 4-tap's negative lobes may ring below zero next to a bright edge: not
    // below the darker neighbour where both are non-negative (8-bit outputs clamp
    // there anyway; float / HDR inputs, deinterlaced in linear light, would keep it).
    let floor_ = min(min(c, e), vec4<f32>(0.0));
    let moving = max(select(clamp(interp, d - diff, d + diff), sp, first_output()), floor_);
    return select(moving, d, still);
#endif
}
#endif

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let s = vec2<i32>(textureDimensions(cur));
    let parity = i32((params.field_order ^ params.subframe) & 1u);
    let u = pos.x / f32(s.x);
#if STAGE == 0
#if MODE == 1
    return vec4<f32>(0.0);
#else
    // Row r of this half-height pass is the missing row 2r + 1 - parity (past the
    // last row when the height is odd and the first row is kept: clamped).
    let y = min(2 * i32(pos.y) + 1 - parity, s.y - 1);
    return reconstruct(s, u, y);
#endif
#else
    let y = i32(pos.y);
#if MODE == 1
    return 0.25 * at(cur, u, row_v(y - 1, s.y)) + 0.5 * at(cur, u, pos.y / f32(s.y))
        + 0.25 * at(cur, u, row_v(y + 1, s.y));
#else
    let kept = at(cur, u, pos.y / f32(s.y));
    let hs = vec2<f32>(textureDimensions(missing));
    let rec = at(missing, u, (f32(y >> 1u) + 0.5) / hs.y);
    return select(rec, kept, (y & 1) == parity);
#endif
#endif
}
