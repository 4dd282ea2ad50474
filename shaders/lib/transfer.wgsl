// Transfer functions and primaries of video signals: the WGSL twin of
// src/pixels/color/ (same published formulas, same absolute scale), for passes
// that decode or encode signals on the GPU: `#include "lib/transfer.wgsl"`.
//
// Working space: linear light, BT.709 primaries, 1.0 = 203 cd/m² (ITU-R BT.2408
// HDR reference white). So PQ 203 cd/m² <-> 1.0 and 1,000 cd/m² <-> 4.93.
//   PQ   SMPTE ST 2084 EOTF and its inverse (signal <-> 0..10,000 cd/m²)
//   HLG  ITU-R BT.2100 OETF, its inverse, and the OOTF for a display of peak Lw
//        (black 0): Fd = Lw Ys^(gamma - 1) E, gamma = 1.2 + 0.42 log10(Lw / 1000)
//   BT.1886 (black 0): L = V^2.4
//   primaries: BT.709 <-> BT.2020 (ITU-R BT.2087 / BT.2407), Display P3 -> BT.709

// SMPTE ST 2084: signal (clamped to [0, 1]) -> cd/m².
fn lib_pq_to_nits(e: f32) -> f32 {
    let m1 = 2610.0 / 16384.0;
    let m2 = 2523.0 / 4096.0 * 128.0;
    let c1 = 3424.0 / 4096.0;
    let c2 = 2413.0 / 4096.0 * 32.0;
    let c3 = 2392.0 / 4096.0 * 32.0;
    let p = pow(clamp(e, 0.0, 1.0), 1.0 / m2);
    return 10000.0 * pow(max(p - c1, 0.0) / (c2 - c3 * p), 1.0 / m1);
}

// SMPTE ST 2084 inverse: cd/m² (clamped to [0, 10000]) -> signal.
fn lib_nits_to_pq(nits: f32) -> f32 {
    let m1 = 2610.0 / 16384.0;
    let m2 = 2523.0 / 4096.0 * 128.0;
    let c1 = 3424.0 / 4096.0;
    let c2 = 2413.0 / 4096.0 * 32.0;
    let c3 = 2392.0 / 4096.0 * 32.0;
    let p = pow(clamp(nits / 10000.0, 0.0, 1.0), m1);
    return pow((c1 + c2 * p) / (1.0 + c3 * p), m2);
}

// PQ signal -> working-space linear (1.0 = 203 cd/m²), per channel.
fn lib_pq_to_linear(e: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(lib_pq_to_nits(e.r), lib_pq_to_nits(e.g), lib_pq_to_nits(e.b)) / 203.0;
}

// Working-space linear -> PQ signal, per channel.
fn lib_linear_to_pq(l: vec3<f32>) -> vec3<f32> {
    let n = l * 203.0;
    return vec3<f32>(lib_nits_to_pq(n.r), lib_nits_to_pq(n.g), lib_nits_to_pq(n.b));
}

// BT.2100 HLG OETF: normalised scene light (clamped to [0, 1]) -> signal.
fn lib_hlg_oetf(e_in: vec3<f32>) -> vec3<f32> {
    let a = 0.17883277;
    let b = 1.0 - 4.0 * a;
    let c = 0.55991073;
    let e = clamp(e_in, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(a * log(max(12.0 * e - b, vec3<f32>(1e-30))) + c, sqrt(3.0 * e), e <= vec3<f32>(1.0 / 12.0));
}

// BT.2100 HLG inverse OETF: signal (clamped to [0, 1]) -> normalised scene light.
fn lib_hlg_inverse_oetf(s_in: vec3<f32>) -> vec3<f32> {
    let a = 0.17883277;
    let b = 1.0 - 4.0 * a;
    let c = 0.55991073;
    let s = clamp(s_in, vec3<f32>(0.0), vec3<f32>(1.0));
    return select((exp((s - c) / a) + b) / 12.0, s * s / 3.0, s <= vec3<f32>(0.5));
}

// HLG system gamma for a display of `peak` cd/m².
fn lib_hlg_gamma(peak: f32) -> f32 {
    return 1.2 + 0.42 * log(peak / 1000.0) / log(10.0);
}

// HLG signal -> working-space linear (display light / 203), for a display of
// `peak` cd/m²; `w` the luminance weights of the signal's primaries.
fn lib_hlg_to_linear(s: vec3<f32>, w: vec3<f32>, peak: f32) -> vec3<f32> {
    let e = lib_hlg_inverse_oetf(s);
    let ys = max(dot(w, e), 0.0);
    let k = select(0.0, peak * pow(ys, lib_hlg_gamma(peak) - 1.0), ys > 0.0);
    return e * k / 203.0;
}

// Working-space linear -> HLG signal (the inverse OOTF, then the OETF).
fn lib_linear_to_hlg(l: vec3<f32>, w: vec3<f32>, peak: f32) -> vec3<f32> {
    let fd = clamp(l * 203.0, vec3<f32>(0.0), vec3<f32>(peak));
    let yd = max(dot(w, fd), 0.0);
    let g = lib_hlg_gamma(peak);
    let k = select(0.0, pow(yd / peak, (1.0 - g) / g) / peak, yd > 0.0);
    return lib_hlg_oetf(fd * k);
}

// BT.1886 with black 0, extended by symmetry: V^2.4 and its inverse.
fn lib_bt1886_to_linear(v: vec3<f32>) -> vec3<f32> {
    return sign(v) * pow(abs(v), vec3<f32>(2.4));
}

fn lib_linear_to_bt1886(l: vec3<f32>) -> vec3<f32> {
    return sign(l) * pow(abs(l), vec3<f32>(1.0 / 2.4));
}

// Linear BT.709 -> linear BT.2020 (ITU-R BT.2087; columns are the images of R, G, B).
fn lib_bt709_to_bt2020(c: vec3<f32>) -> vec3<f32> {
    let m = mat3x3<f32>(
        vec3<f32>(0.6274039, 0.0690973, 0.0163914),
        vec3<f32>(0.3292830, 0.9195404, 0.0880133),
        vec3<f32>(0.0433131, 0.0113623, 0.8955953),
    );
    return m * c;
}

// Linear BT.2020 -> linear BT.709 (ITU-R BT.2407).
fn lib_bt2020_to_bt709(c: vec3<f32>) -> vec3<f32> {
    let m = mat3x3<f32>(
        vec3<f32>(1.6604910, -0.1245505, -0.0181508),
        vec3<f32>(-0.5876411, 1.1328999, -0.1005789),
        vec3<f32>(-0.0728499, -0.0083494, 1.1187297),
    );
    return m * c;
}

// Linear Display P3 -> linear BT.709.
fn lib_p3_to_bt709(c: vec3<f32>) -> vec3<f32> {
    let m = mat3x3<f32>(
        vec3<f32>(1.2249401, -0.0420569, -0.0196376),
        vec3<f32>(-0.2249404, 1.0420571, -0.0786361),
        vec3<f32>(0.0, 0.0, 1.0982735),
    );
    return m * c;
}
