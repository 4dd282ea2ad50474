// tonemap: maps linear HDR colour to display-referred linear [0, 1]:
//   x = max(in, 0) * 2^exposure
//   OPERATOR = 0 (Reinhard), per channel:
//                             white <= 0: y = x / (1 + x)
//                             white  > 0: y = x (1 + x / white^2) / (1 + x)   (extended: white -> 1)
//   OPERATOR = 1 (ACES, Narkowicz 2015 filmic fit), per channel:
//                             y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
//   OPERATOR = 2 (Khronos PBR Neutral, the published specification): on the
//                             colour, hue-preserving; identity below 0.76 (after
//                             the toe offset), then a highlight compression that
//                             desaturates towards white
//   OPERATOR = 3 (AgX, Troy Sobotka's, as in Blender 4): inset matrix, log2
//                             encoding over [-12.47393, 4.026069] EV, the base
//                             contrast sigmoid as the 6th-order polynomial fit of
//                             Benjamin Wrensch's "minimal AgX", LOOK = 1 the
//                             punchy look (ASC CDL power 1.35, saturation 1.4),
//                             outset (inverse inset) matrix, then the 2.2 power
//                             back to linear display light
//   OPERATOR = 4 (ITU-R BT.2390 EETF, for HDR video): in the PQ domain, on the
//                             largest BT.2020 component of the colour (libplacebo's
//                             "max" mode, hue-preserving), from the source peak
//                             (source_peak cd/m², or the measured one of `state`;
//                             black source_black) to a display of target_peak and
//                             target_peak / contrast black; the colour is scaled
//                             by the ratio; y = the display's BT.1886 signal
//                             (black Lb) raised to 2.4, so that fxrun's 2.4-gamma
//                             SDR output writes that signal
//   GAMUT = 1 (desaturate): before the operator, colours with a negative BT.709
//                             component (outside the gamut, e.g. from BT.2020) are
//                             moved towards their luminance until none is; after
//                             BT.2390, colours above 1 likewise towards white, so
//                             hue is kept instead of clipping each channel.
//                             GAMUT = 0: channels clipped.
//   out = clamp(y, 0, 1); alpha is kept.
#define OPERATOR 1
#define LOOK 0
#define GAMUT 1

#include "lib/transfer.wgsl"

@group(0) @binding(0) var img: texture_2d<f32>;

struct Params {
    exposure: f32,    // @default(0) @range(-20, 20) exposure in stops applied before the curve
    white: f32,       // @default(0) @range(0, 65000) Reinhard extended: the value mapped to 1 (0: plain Reinhard)
    source_peak: f32, // @default(0) @range(0, 10000) BT.2390: the source's peak in cd/m² (0: measured per frame)
    target_peak: f32, // @default(203) @range(80, 10000) BT.2390: the display's peak in cd/m² (output 1.0)
    knee: f32,        // @default(0.5) @range(0.5, 2) BT.2390: knee offset (ks = (1 + knee) maxLum - knee; 0.5 is BT.2390's)
    source_black: f32, // @default(0.005) @range(0, 100) BT.2390: the source's black in cd/m²
    contrast: f32,    // @default(1000) @range(0, 1000000) BT.2390: the display's contrast (black = target_peak / contrast; 0: black 0)
    // Taken so that `tonemap` and `tonemap_video` have the same parameters; used by
    // tonemap_video's peak pass only.
    smoothing: f32,   // @default(20) @range(1, 1000) tonemap_video: frames the measured peak is averaged over
    scene_low: f32,   // @default(1) @range(0, 100) tonemap_video: average-brightness change (% PQ) where a scene cut starts to count
    scene_high: f32,  // @default(3) @range(0, 100) tonemap_video: average-brightness change (% PQ) that restarts the measurement
}
@group(0) @binding(1) var<uniform> params: Params;
// The measured peak (r: PQ code): the last tonemap_peak level (tonemap), or
// tonemap_peak_adapt (tonemap_video: smoothed over frames).
@group(0) @binding(2) var state: texture_2d<f32>;

// Khronos PBR Neutral (https://github.com/KhronosGroup/ToneMapping, PBR_Neutral):
// start compression 0.8 - 0.04, desaturation 0.15.
fn pbr_neutral(c_in: vec3<f32>) -> vec3<f32> {
    let start = 0.8 - 0.04;
    let desaturation = 0.15;
    var c = c_in;
    let x = min(c.r, min(c.g, c.b));
    let offset = select(0.04, x - 6.25 * x * x, x < 0.08);
    c -= offset;
    let peak = max(c.r, max(c.g, c.b));
    if peak < start {
        return c;
    }
    let d = 1.0 - start;
    let new_peak = 1.0 - d * d / (peak + d - start);
    c *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(c, vec3<f32>(new_peak), g);
}

// AgX base contrast: the sigmoid on the log-encoded [0, 1] value, as a
// polynomial (mean error 1.85e-4 against Blender's LUT, per its author).
fn agx_contrast(x: vec3<f32>) -> vec3<f32> {
    let x2 = x * x;
    let x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232;
}

fn agx(c: vec3<f32>) -> vec3<f32> {
    // inset (columns: the images of red, green and blue)
    let inset = mat3x3<f32>(
        vec3<f32>(0.842479062253094, 0.0423282422610123, 0.0423756549057051),
        vec3<f32>(0.0784335999999992, 0.878468636469772, 0.0784336),
        vec3<f32>(0.0792237451477643, 0.0791661274605434, 0.879142973793104),
    );
    let outset = mat3x3<f32>(
        vec3<f32>(1.19687900512017, -0.0528968517574562, -0.0529716355144438),
        vec3<f32>(-0.0980208811401368, 1.15190312990417, -0.0980434501171241),
        vec3<f32>(-0.0990297440797205, -0.0989611768448433, 1.15107367264116),
    );
    let min_ev = -12.47393;
    let max_ev = 4.026069;
    var v = inset * c;
    v = clamp(log2(max(v, vec3<f32>(1e-10))), vec3<f32>(min_ev), vec3<f32>(max_ev));
    v = (v - min_ev) / (max_ev - min_ev);
    v = agx_contrast(v);
#if LOOK == 1
    // punchy: slope 1, offset 0, power 1.35, saturation 1.4 about the Rec.709
    // luma of the value before the power
    let luma = dot(v, vec3<f32>(0.2126, 0.7152, 0.0722));
    v = pow(max(v, vec3<f32>(0.0)), vec3<f32>(1.35));
    v = luma + 1.4 * (v - luma);
#endif
    v = outset * v;
    return pow(max(v, vec3<f32>(0.0)), vec3<f32>(2.2));
}

// BT.709 luminance.
fn tm_luma(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Move `c` towards its luminance until no channel is below 0 (out-of-gamut
// colours desaturated rather than clipped); in-gamut colours are unchanged.
fn tm_gamut_floor(c: vec3<f32>) -> vec3<f32> {
    let y = max(tm_luma(c), 0.0);
    let lo = min(c.r, min(c.g, c.b));
    if (lo >= 0.0) {
        return c;
    }
    let t = y / max(y - lo, 1e-12);
    return vec3<f32>(y) + (c - vec3<f32>(y)) * t;
}

// Move `c` towards white (its luminance) until no channel is above 1.
fn tm_gamut_ceiling(c: vec3<f32>) -> vec3<f32> {
    let y = tm_luma(c);
    let hi = max(c.r, max(c.g, c.b));
    if (hi <= 1.0 || y >= 1.0) {
        return c;
    }
    let t = (1.0 - y) / max(hi - y, 1e-12);
    return vec3<f32>(y) + (c - vec3<f32>(y)) * t;
}

// ITU-R BT.2390 EETF (report BT.2390, section 5.4) on a PQ code `e`, from a
// source mastered between src_min and src_max cd/m² to a display of dst_min to
// dst_max cd/m²; returns the PQ code. In the normalised PQ range of the source:
// the Hermite spline above the knee ks = (1 + knee) maxLum - knee, then the black
// level lift E + minLum (1 - E)^4 (scaled so that maxLum stays the peak, as
// libplacebo does).
fn tm_bt2390(e: f32, src_min: f32, src_max: f32, dst_min: f32, dst_max: f32, knee: f32) -> f32 {
    let lo = lib_nits_to_pq(src_min);
    let hi = lib_nits_to_pq(src_max);
    let range = max(hi - lo, 1e-6);
    let min_lum = max(lib_nits_to_pq(dst_min) - lo, 0.0) / range;
    let max_lum = min((lib_nits_to_pq(dst_max) - lo) / range, 1.0);
    var x = (e - lo) / range;
    let ks = (1.0 + knee) * max_lum - knee;
    if (ks < 1.0 && x >= ks) {
        let t = (x - ks) / (1.0 - ks);
        let t2 = t * t;
        let t3 = t2 * t;
        x = (2.0 * t3 - 3.0 * t2 + 1.0) * ks + (t3 - 2.0 * t2 + t) * (1.0 - ks) + (-2.0 * t3 + 3.0 * t2) * max_lum;
    }
    if (x < 1.0 && min_lum > 0.0) {
        let bp = min(1.0 / min_lum, 4.0);
        let gain = select(1.0, 1.0 / (1.0 + min_lum / max_lum * pow(1.0 - max_lum, bp)), max_lum < 1.0);
        x += min_lum * pow(max(1.0 - x, 0.0), bp);
        x = gain * (x - min_lum) + min_lum;
    }
    return x * range + lo;
}

// BT.2390 on the largest BT.2020 component, the colour scaled by the ratio, for
// a display of target_peak cd/m² and target_peak / contrast black. Returns the
// BT.1886 signal of that display (Lb = black, Lw = peak) raised to 2.4: the
// linear value whose pure 2.4 gamma encoding (fxrun's SDR output) is that signal.
fn tm_eetf(x: vec3<f32>) -> vec3<f32> {
    var src = params.source_peak;
    if (src <= 0.0) {
        src = lib_pq_to_nits(textureLoad(state, vec2<i32>(0), 0).r);
    }
    let dst = params.target_peak;
    src = max(src, dst);
    let dst_min = select(0.0, dst / params.contrast, params.contrast > 0.0);
    let c = lib_bt709_to_bt2020(x);
    let sig = min(max(max(c.r, max(c.g, c.b)), 0.0) * 203.0, src);
    if (sig <= 0.0) {
        return vec3<f32>(0.0);
    }
    let e = tm_bt2390(lib_nits_to_pq(sig), params.source_black, src, dst_min, dst, params.knee);
    // Display light relative to the peak (1 = target_peak).
    let l = x * 203.0 * (lib_pq_to_nits(e) / max(sig, dst_min)) / dst;
    let lb = pow(dst_min / dst, 1.0 / 2.4);
    let v = (pow(max(l, vec3<f32>(0.0)), vec3<f32>(1.0 / 2.4)) - lb) / (1.0 - lb);
    return sign(v) * pow(abs(v), vec3<f32>(2.4));
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
#if GAMUT == 1
    let x = max(tm_gamut_floor(c.rgb), vec3<f32>(0.0)) * exp2(params.exposure);
#else
    let x = max(c.rgb, vec3<f32>(0.0)) * exp2(params.exposure);
#endif
#if OPERATOR == 0
    var y = x / (1.0 + x);
    if (params.white > 0.0) {
        y *= 1.0 + x / (params.white * params.white);
    }
#elif OPERATOR == 1
    let y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
#elif OPERATOR == 2
    let y = pbr_neutral(x);
#elif OPERATOR == 3
    let y = agx(x);
#else
#if GAMUT == 1
    let y = tm_gamut_ceiling(tm_eetf(x));
#else
    let y = tm_eetf(x);
#endif
#endif
    return vec4<f32>(clamp(y, vec3<f32>(0.0), vec3<f32>(1.0)), c.a);
}
