// deint: reconstructs one field of an interlaced frame as a progressive image
// (the `deinterlace` effect; the maths is documented in effects/deinterlace.fx).
//
// Rows y = 0, 2, 4, ... are the top field, y = 1, 3, 5, ... the bottom field.
// The kept field has parity p = field_order XOR subframe (tff = 0, bff = 1): the
// first field in time at subframe 0, the second at subframe 1. Its rows are copied;
// the rows of the other parity ("missing" rows) are reconstructed:
//   MODE 0 (bob)       (cur[y-1] + cur[y+1]) / 2
//   MODE 1 (blend)     every row: (cur[y-1] + 2 cur[y] + cur[y+1]) / 4
//   MODE 2 (adaptive)  yadif-style: edge-directed spatial prediction (limited to the
//                      range of the rows above and below) clamped around a temporal
//                      prediction by a motion-dependent margin.
// Rows outside the image are reflected onto rows of the same parity (y-1 at the top
// reads y+1, ...), columns are clamped.
//
// Two passes (STAGE), so that the costly reconstruction runs on the missing rows
// only (a CPU rasteriser shades 2x2 quads, so a per-row branch in one full-size
// pass runs both sides for every pixel; at 720x576 one pass took 3.7 s for 30
// frames against 2.0 s for the two):
//   STAGE 0  `missing`: half height (row r is image row 2r + 1 - p); bob and
//            adaptive reconstruct the missing rows here (blend writes nothing useful)
//   STAGE 1  `weave`: full size; kept rows from cur, missing rows from `missing`
//            (blend computes every row here)
#ifndef MODE
#define MODE 2
#endif
#ifndef STAGE
#define STAGE 0
#endif

@group(0) @binding(0) var cur: texture_2d<f32>;
#if STAGE == 0
@group(0) @binding(1) var prev: texture_2d<f32>;
@group(0) @binding(2) var next: texture_2d<f32>;
// Nearest, clamp-to-edge; used for all three inputs (see `ld`).
@group(0) @binding(4) var cur_sampler: sampler;
#else
@group(0) @binding(1) var missing: texture_2d<f32>;
// Nearest; the weave reads both inputs with samples at texel centres (cheaper than
// sRGB textureLoads on lavapipe: 1080p weave about 27 against 39 ms).
@group(0) @binding(4) var cur_sampler: sampler;
#endif

struct Params {
    field_order: u32, // @default(0) @range(0, 1) 0: top field first (tff), 1: bottom field first (bff)
    threshold: f32,   // @default(0) @range(0, 1) adaptive: temporal difference at or below which a pixel is still (the temporal prediction is used as it is)
    subframe: u32,
}
@group(0) @binding(3) var<uniform> params: Params;

// Bias in favour of the vertical direction in the edge search (sum over r, g, b).
const VERTICAL_BIAS: f32 = 0.002;

fn fold_row(y: i32, h: i32) -> i32 {
    var r = y;
    if (r < 0) {
        r = r + 2;
    } else if (r >= h) {
        r = r - 2;
    }
    return clamp(r, 0, h - 1);
}

// A texel of `t` (of size `s`) at column x (clamped) and row y (folded). The
// reconstruction reads it with a nearest-filter sample at the texel's centre, not
// textureLoad: the same value, but on lavapipe an rgba8-srgb load costs about 3.5
// times a plain rgba8 one (the sRGB decode) and the sample path is cheaper (the
// `rows` pass, 720x576: about 40 against 65 ms).
fn ld(t: texture_2d<f32>, s: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
#if STAGE == 0
    let uv = (vec2<f32>(f32(clamp(x, 0, s.x - 1)), f32(fold_row(y, s.y))) + 0.5) / vec2<f32>(s);
    return textureSampleLevel(t, cur_sampler, uv, 0.0);
#else
    return textureLoad(t, vec2<i32>(clamp(x, 0, s.x - 1), fold_row(y, s.y)), 0);
#endif
}

// Sum of the absolute r, g, b differences (the edge score).
fn dist(a: vec4<f32>, b: vec4<f32>) -> f32 {
    let d = abs(a.rgb - b.rgb);
    return d.r + d.g + d.b;
}

#if STAGE == 0
// Edge-directed interpolation of the missing row y from rows y - 1 and y + 1: the
// direction j (row y-1 at x + j, row y+1 at x - j) of least score among 0, -1, -2,
// +1, +2 (the wider slope is only tried when the narrower one on its side won),
// the score of j being the differences along it over three neighbouring columns.
// The 7 + 7 texels of the two rows are loaded once.
fn spatial(s: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
    let u_3 = ld(cur, s, x - 3, y - 1);
    let u_2 = ld(cur, s, x - 2, y - 1);
    let u_1 = ld(cur, s, x - 1, y - 1);
    let u0 = ld(cur, s, x, y - 1);
    let u1 = ld(cur, s, x + 1, y - 1);
    let u2 = ld(cur, s, x + 2, y - 1);
    let u3 = ld(cur, s, x + 3, y - 1);
    let d_3 = ld(cur, s, x - 3, y + 1);
    let d_2 = ld(cur, s, x - 2, y + 1);
    let d_1 = ld(cur, s, x - 1, y + 1);
    let d0 = ld(cur, s, x, y + 1);
    let d1 = ld(cur, s, x + 1, y + 1);
    let d2 = ld(cur, s, x + 2, y + 1);
    let d3 = ld(cur, s, x + 3, y + 1);
    var best = dist(u_1, d_1) + dist(u0, d0) + dist(u1, d1) - VERTICAL_BIAS;
    var pred = 0.5 * (u0 + d0);
    // side -1: j = -1, then -2
    let sm1 = dist(u_2, d0) + dist(u_1, d1) + dist(u0, d2);
    let sm2 = dist(u_3, d1) + dist(u_2, d2) + dist(u_1, d3);
    if (sm1 < best) {
        best = sm1;
        pred = 0.5 * (u_1 + d1);
        if (sm2 < best) {
            best = sm2;
            pred = 0.5 * (u_2 + d2);
        }
    }
    // side +1: j = 1, then 2
    let sp1 = dist(u0, d_2) + dist(u1, d_1) + dist(u2, d0);
    let sp2 = dist(u1, d_3) + dist(u2, d_2) + dist(u3, d_1);
    if (sp1 < best) {
        best = sp1;
        pred = 0.5 * (u1 + d_1);
        if (sp2 < best) {
            pred = 0.5 * (u2 + d_2);
        }
    }
    return pred;
}

// The missing field's rows at the output's time, before (t0) and after (t1): the
// fields of the missing parity nearest in time are in (prev, cur) when the first
// field is kept (subframe 0) and in (cur, next) when the second is.
fn t0(s: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
    if (params.subframe == 0u) {
        return ld(prev, s, x, y);
    }
    return ld(cur, s, x, y);
}

fn t1(s: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
    if (params.subframe == 0u) {
        return ld(cur, s, x, y);
    }
    return ld(next, s, x, y);
}

// The reconstructed missing row y at column x (bob or adaptive).
fn reconstruct(s: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
#if MODE == 0
    return 0.5 * (ld(cur, s, x, y - 1) + ld(cur, s, x, y + 1));
#else
    let c = ld(cur, s, x, y - 1);
    let e = ld(cur, s, x, y + 1);
    let a = t0(s, x, y);
    let b = t1(s, x, y);
    // Temporal prediction and motion: the missing row's change across the output
    // time, and the kept rows' change from the previous and to the next frame.
    let d = 0.5 * (a + b);
    let td0 = abs(a - b);
    let td1 = 0.5 * (abs(ld(prev, s, x, y - 1) - c) + abs(ld(prev, s, x, y + 1) - e));
    let td2 = 0.5 * (abs(ld(next, s, x, y - 1) - c) + abs(ld(next, s, x, y + 1) - e));
    var diff = max(0.5 * td0, max(td1, td2));
    let still = diff <= vec4<f32>(params.threshold);
    // Spatial-temporal check: widen the margin where the temporal prediction is an
    // extremum against the rows above and below that the field two rows away
    // (predicted the same way) does not confirm.
    let bb = 0.5 * (t0(s, x, y - 2) + t1(s, x, y - 2));
    let ff = 0.5 * (t0(s, x, y + 2) + t1(s, x, y + 2));
    let hi = max(max(d - e, d - c), min(bb - c, ff - e));
    let lo = min(min(d - e, d - c), max(bb - c, ff - e));
    diff = max(diff, max(lo, -hi));
    // The edge-directed value, kept between the rows above and below (a wrong slope
    // across an object's edge cannot invent a value), then clamped around d.
    let sp = clamp(spatial(s, x, y), min(c, e), max(c, e));
    let moving = clamp(sp, d - diff, d + diff);
    return select(moving, d, still);
#endif
}

#endif

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let s = vec2<i32>(textureDimensions(cur));
    let x = i32(pos.x);
    let parity = i32((params.field_order ^ params.subframe) & 1u);
#if STAGE == 0
#if MODE == 1
    return vec4<f32>(0.0);
#else
    // Row r of this half-height pass is the missing row 2r + 1 - parity (past the
    // last row when the height is odd and the first row is kept: clamped).
    let y = min(2 * i32(pos.y) + 1 - parity, s.y - 1);
    return reconstruct(s, x, y);
#endif
#else
    let y = i32(pos.y);
#if MODE == 1
    return 0.25 * ld(cur, s, x, y - 1) + 0.5 * ld(cur, s, x, y) + 0.25 * ld(cur, s, x, y + 1);
#else
    let kept = textureSampleLevel(cur, cur_sampler, pos.xy / vec2<f32>(s), 0.0);
    let hs = vec2<f32>(textureDimensions(missing));
    let rec = textureSampleLevel(missing, cur_sampler, vec2<f32>(pos.x, f32(y >> 1u) + 0.5) / hs, 0.0);
    return select(rec, kept, (y & 1) == parity);
#endif
#endif
}
