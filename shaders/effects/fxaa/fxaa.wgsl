// fxaa: fast approximate anti-aliasing in the manner of FXAA 3.11 "quality"
// (T. Lottes, NVIDIA 2011), written from the published description. See
// effects/fxaa.fx for the algorithm in words.
//
// Two views of the same image: `img` (linear light) gives the colour that is
// returned or resampled; `enc` (bound with COLORSPACE = srgb) gives the luma, the
// Rec.709 weighted sum of sRGB-encoded values, as FXAA computes it on
// gamma-encoded frames. For 8-bit inputs `enc` is the raw view of the same
// texture, so the many luma taps skip the sRGB decode. Pixels whose local
// contrast is below the threshold are returned exactly as loaded.
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;
@group(0) @binding(3) var enc: texture_2d<f32>;
@group(0) @binding(4) var enc_sampler: sampler;

struct Params {
    contrast_threshold: f32, // @default(0.125) @range(0.01, 1) minimum local contrast, relative to the brightest neighbour, to process a pixel
    absolute_threshold: f32, // @default(0.0312) @range(0, 1) minimum local contrast in luma units (skips dark noise)
    subpix: f32,             // @default(0.75) @range(0, 1) amount of sub-pixel aliasing removal (0: edges only)
    img_texel: vec2<f32>,
}
@group(0) @binding(2) var<uniform> params: Params;

// Edge-end search: step sizes in pixels after the first step of 1 (FXAA 3.11's
// default preset 12: reach 20.5 px each way in 5 taps).
const STEPS = array<f32, 4>(1.5, 2.0, 4.0, 12.0);

fn luma(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn luma_at(uv: vec2<f32>) -> f32 {
    return luma(textureSampleLevel(enc, enc_sampler, uv, 0.0).rgb);
}

fn load_luma(p: vec2<i32>, hi: vec2<i32>) -> f32 {
    return luma(textureLoad(enc, clamp(p, vec2<i32>(0), hi), 0).rgb);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>, @location(0) uv_in: vec2<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pos.xy);
    let hi = vec2<i32>(textureDimensions(img)) - 1;
    let lm = load_luma(p, hi);
    var ln = load_luma(p + vec2<i32>(0, -1), hi);
    var ls = load_luma(p + vec2<i32>(0, 1), hi);
    let le = load_luma(p + vec2<i32>(1, 0), hi);
    let lw = load_luma(p + vec2<i32>(-1, 0), hi);

    // 1. Local contrast test: most pixels leave here, unchanged.
    let lmax = max(max(max(ln, ls), max(le, lw)), lm);
    let lmin = min(min(min(ln, ls), min(le, lw)), lm);
    let range = lmax - lmin;
    if (range < max(params.absolute_threshold, lmax * params.contrast_threshold)) {
        return textureLoad(img, p, 0);
    }
    let lnw = load_luma(p + vec2<i32>(-1, -1), hi);
    let lne = load_luma(p + vec2<i32>(1, -1), hi);
    let lsw = load_luma(p + vec2<i32>(-1, 1), hi);
    let lse = load_luma(p + vec2<i32>(1, 1), hi);

    // 2. Sub-pixel aliasing: how far the centre is from its 3x3 low-pass.
    let lowpass = (2.0 * (ln + ls + le + lw) + (lnw + lne + lsw + lse)) / 12.0;
    let sub_a = clamp(abs(lowpass - lm) / range, 0.0, 1.0);
    let sub_b = (-2.0 * sub_a + 3.0) * sub_a * sub_a; // smoothstep
    let sub_blend = sub_b * sub_b * params.subpix;

    // 3. Edge orientation from second differences along rows and columns.
    let edge_h = abs(-2.0 * lw + lnw + lsw) + 2.0 * abs(-2.0 * lm + ln + ls) + abs(-2.0 * le + lne + lse);
    let edge_v = abs(-2.0 * ln + lnw + lne) + 2.0 * abs(-2.0 * lm + lw + le) + abs(-2.0 * ls + lsw + lse);
    let horizontal = edge_h >= edge_v; // the edge runs along x; blend across it in y
    var step_len = params.img_texel.x;
    if (horizontal) {
        step_len = params.img_texel.y;
    } else {
        ln = lw;
        ls = le;
    }

    // 4. Which side of the centre the edge lies on: the steeper neighbour.
    let grad_n = abs(ln - lm);
    let grad_s = abs(ls - lm);
    let pair_n = grad_n >= grad_s;
    let gradient = max(grad_n, grad_s);
    var pair_luma = (ls + lm) * 0.5;
    if (pair_n) {
        step_len = -step_len;
        pair_luma = (ln + lm) * 0.5;
    }

    // 5. Search along the edge, on the line between the centre and that neighbour,
    //    in both directions until the average luma there departs from the pair's.
    var pos_b = uv_in;
    var along = vec2<f32>(params.img_texel.x, 0.0);
    if (horizontal) {
        pos_b.y += 0.5 * step_len;
    } else {
        pos_b.x += 0.5 * step_len;
        along = vec2<f32>(0.0, params.img_texel.y);
    }
    let threshold = gradient * 0.25;
    var pos_n = pos_b - along;
    var pos_p = pos_b + along;
    var end_n = luma_at(pos_n) - pair_luma;
    var end_p = luma_at(pos_p) - pair_luma;
    var done_n = abs(end_n) >= threshold;
    var done_p = abs(end_p) >= threshold;
    for (var i = 0; i < 4; i++) {
        if (done_n && done_p) {
            break;
        }
        if (!done_n) {
            pos_n -= along * STEPS[i];
            end_n = luma_at(pos_n) - pair_luma;
            done_n = abs(end_n) >= threshold;
        }
        if (!done_p) {
            pos_p += along * STEPS[i];
            end_p = luma_at(pos_p) - pair_luma;
            done_p = abs(end_p) >= threshold;
        }
    }

    // 6. Distance to the nearer end gives how far to shift the sample across the edge
    //    (a staircase step becomes a ramp). Only if that end turns the right way.
    var dst_n = uv_in.y - pos_n.y;
    var dst_p = pos_p.y - uv_in.y;
    if (horizontal) {
        dst_n = uv_in.x - pos_n.x;
        dst_p = pos_p.x - uv_in.x;
    }
    let centre_below = lm - pair_luma < 0.0;
    let nearer_n = dst_n < dst_p;
    let dst = min(dst_n, dst_p);
    let end_luma = select(end_p, end_n, nearer_n);
    let good_span = (end_luma < 0.0) != centre_below;
    let span_offset = select(0.0, 0.5 - dst / (dst_n + dst_p), good_span);
    let offset = max(span_offset, sub_blend);
    // A shift below 1/256 texel would change the colour by less than 1/256 of the
    // local contrast (e.g. a straight horizontal edge with subpix = 0): keep the
    // pixel exactly rather than resample it with the sampler's rounding.
    if (offset < 1.0 / 256.0) {
        return textureLoad(img, p, 0);
    }

    var uv = uv_in;
    if (horizontal) {
        uv.y += offset * step_len;
    } else {
        uv.x += offset * step_len;
    }
    return textureSampleLevel(img, img_sampler, uv, 0.0);
}
