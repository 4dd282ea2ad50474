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
@group(0) @binding(0) var cur: texture_2d<f32>;
@group(0) @binding(1) var prev: texture_2d<f32>;
@group(0) @binding(2) var next: texture_2d<f32>;

struct Params {
    field_order: u32, // @default(0) @range(0, 1) 0: top field first (tff), 1: bottom field first (bff)
    threshold: f32,   // @default(0) @range(0, 1) adaptive: temporal difference at or below which a pixel is still (the temporal prediction is used as it is)
    subframe: u32,
}
@group(0) @binding(3) var<uniform> params: Params;

#ifndef MODE
#define MODE 2
#endif

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

fn ld(t: texture_2d<f32>, x: i32, y: i32) -> vec4<f32> {
    let s = vec2<i32>(textureDimensions(t));
    return textureLoad(t, vec2<i32>(clamp(x, 0, s.x - 1), fold_row(y, s.y)), 0);
}

// Sum of the absolute r, g, b differences (the edge score).
fn dist(a: vec4<f32>, b: vec4<f32>) -> f32 {
    let d = abs(a.rgb - b.rgb);
    return d.r + d.g + d.b;
}

// Score of the direction j: the lines above and below compared along the slope
// (x + j above, x - j below) over three neighbouring columns.
fn score(x: i32, y: i32, j: i32) -> f32 {
    return dist(ld(cur, x + j - 1, y - 1), ld(cur, x - j - 1, y + 1))
        + dist(ld(cur, x + j, y - 1), ld(cur, x - j, y + 1))
        + dist(ld(cur, x + j + 1, y - 1), ld(cur, x - j + 1, y + 1));
}

fn along(x: i32, y: i32, j: i32) -> vec4<f32> {
    return 0.5 * (ld(cur, x + j, y - 1) + ld(cur, x - j, y + 1));
}

// Edge-directed interpolation of the missing row y from rows y - 1 and y + 1:
// the direction of least score among 0, -1, -2, +1, +2 (the wider slope is only
// tried when the narrower one on its side won).
fn spatial(x: i32, y: i32) -> vec4<f32> {
    var best = score(x, y, 0) - VERTICAL_BIAS;
    var pred = along(x, y, 0);
    for (var side = -1; side <= 1; side = side + 2) {
        let s1 = score(x, y, side);
        if (s1 < best) {
            best = s1;
            pred = along(x, y, side);
            let s2 = score(x, y, 2 * side);
            if (s2 < best) {
                best = s2;
                pred = along(x, y, 2 * side);
            }
        }
    }
    return pred;
}

// The missing field's rows at the output's time, before (t0) and after (t1): the
// fields of the missing parity nearest in time are in (prev, cur) when the first
// field is kept (subframe 0) and in (cur, next) when the second is.
fn t0(x: i32, y: i32) -> vec4<f32> {
    if (params.subframe == 0u) {
        return ld(prev, x, y);
    }
    return ld(cur, x, y);
}

fn t1(x: i32, y: i32) -> vec4<f32> {
    if (params.subframe == 0u) {
        return ld(cur, x, y);
    }
    return ld(next, x, y);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let x = i32(pos.x);
    let y = i32(pos.y);
    let parity = i32((params.field_order ^ params.subframe) & 1u);
#if MODE == 1
    return 0.25 * ld(cur, x, y - 1) + 0.5 * ld(cur, x, y) + 0.25 * ld(cur, x, y + 1);
#else
    if ((y & 1) == parity) {
        return ld(cur, x, y);
    }
#if MODE == 0
    return 0.5 * (ld(cur, x, y - 1) + ld(cur, x, y + 1));
#else
    let c = ld(cur, x, y - 1);
    let e = ld(cur, x, y + 1);
    let a = t0(x, y);
    let b = t1(x, y);
    // Temporal prediction and motion: the missing row's change across the output
    // time, and the kept rows' change from the previous and to the next frame.
    let d = 0.5 * (a + b);
    let td0 = abs(a - b);
    let td1 = 0.5 * (abs(ld(prev, x, y - 1) - c) + abs(ld(prev, x, y + 1) - e));
    let td2 = 0.5 * (abs(ld(next, x, y - 1) - c) + abs(ld(next, x, y + 1) - e));
    var diff = max(0.5 * td0, max(td1, td2));
    let still = diff <= vec4<f32>(params.threshold);
    // Spatial-temporal check: widen the margin where the temporal prediction is an
    // extremum against the rows above and below that the field two rows away
    // (predicted the same way) does not confirm.
    let bb = 0.5 * (t0(x, y - 2) + t1(x, y - 2));
    let ff = 0.5 * (t0(x, y + 2) + t1(x, y + 2));
    let hi = max(max(d - e, d - c), min(bb - c, ff - e));
    let lo = min(min(d - e, d - c), max(bb - c, ff - e));
    diff = max(diff, max(lo, -hi));
    // The edge-directed value, kept between the rows above and below (a wrong slope
    // across an object's edge cannot invent a value), then clamped around d.
    let sp = clamp(spatial(x, y), min(c, e), max(c, e));
    let moving = clamp(sp, d - diff, d + diff);
    return select(moving, d, still);
#endif
#endif
}
