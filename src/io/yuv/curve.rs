//! The sRGB curve in vectorisable form, and rounding to sample codes.

use super::super::srgb;

// The sRGB curve, vectorisable: below the knee the exact linear segment, above it a
// polynomial fitted (least squares on Chebyshev nodes, evaluated in f32 on t in [-1, 1]).
// Errors against the exact formula: decode below 3e-6, encode below 4e-6 (0.001 of an
// 8-bit code); see the unit test.

/// Decode: `((x + 0.055) / 1.055)^2.4` on [0.04045, 1], t = (2x - 1.04045) / 0.95955.
pub(crate) const DEC_POLY: [f32; 9] = [
    0.2332408,
    0.46688867,
    0.27259746,
    0.030351264,
    -0.0038336907,
    0.0008825551,
    -0.0002557971,
    0.00031066535,
    -0.00018283911,
];
pub(crate) const DEC_T_SCALE: f32 = 2.0 / (1.0 - 0.04045);
pub(crate) const DEC_T_OFFSET: f32 = -(1.0 + 0.04045) / (1.0 - 0.04045);

/// Encode: `1.055 x^(1/2.4) - 0.055` as a polynomial in s = x^(1/4) on
/// [0.0031308^(1/4), 1], t = (2s - 1 - s0) / (1 - s0).
pub(crate) const ENC_POLY: [f32; 8] = [
    0.41838986,
    0.48712528,
    0.10025644,
    -0.00687218,
    0.0013879355,
    -0.0004124164,
    0.00018937996,
    -0.0000644815,
];
pub(crate) const ENC_S0: f32 = 0.236_545_03;
pub(crate) const ENC_T_SCALE: f32 = 2.0 / (1.0 - ENC_S0);
pub(crate) const ENC_T_OFFSET: f32 = -(1.0 + ENC_S0) / (1.0 - ENC_S0);

#[inline(always)]
pub(crate) fn horner<const N: usize>(c: &[f32; N], t: f32) -> f32 {
    let mut acc = c[N - 1];
    for i in (0..N - 1).rev() {
        acc = acc * t + c[i];
    }
    acc
}

/// sRGB-encoded value in [0, 1] to linear light. Branch-free (both sides are computed
/// and one selected), so loops over it vectorise.
#[inline(always)]
pub(crate) fn srgb_decode_unit(x: f32) -> f32 {
    let p = horner(&DEC_POLY, x * DEC_T_SCALE + DEC_T_OFFSET);
    segments(x, 0.04045, x * (1.0 / 12.92), p)
}

/// An sRGB curve in [0, 1] from both of its segments, computed: `lin` up to `knee`,
/// `poly` above it, and exactly 1 at 1 (the decoding polynomial is 1.2e-6 short
/// there).
#[inline(always)]
fn segments(x: f32, knee: f32, lin: f32, poly: f32) -> f32 {
    let v = if x <= knee { lin } else { poly };
    if x >= 1.0 {
        1.0
    } else {
        v
    }
}

/// sRGB-encoded value to linear light for any `x`: [`srgb_decode_unit`] in [0, 1], the
/// formula's linear segment below 0, its power law above 1.
#[inline]
pub(crate) fn srgb_decode(x: f32) -> f32 {
    if x > 1.0 {
        srgb::srgb_to_linear(x)
    } else {
        srgb_decode_unit(x)
    }
}

/// Linear light in [0, 1] to an sRGB-encoded value, branch-free like
/// [`srgb_decode_unit`]; NaN gives NaN.
#[inline(always)]
pub(crate) fn srgb_encode_unit(x: f32) -> f32 {
    let s = x.sqrt().sqrt();
    let p = horner(&ENC_POLY, s * ENC_T_SCALE + ENC_T_OFFSET);
    segments(x, 0.003_130_8, x * 12.92, p)
}

/// Linear light to an sRGB-encoded value for any `x` (see [`srgb_decode`]).
#[inline]
pub(crate) fn srgb_encode(x: f32) -> f32 {
    if x > 1.0 {
        srgb::linear_to_srgb(x)
    } else if x < 0.0 {
        x * 12.92
    } else {
        srgb_encode_unit(x)
    }
}

/// Round to an 8-bit code (ties to even), saturating; NaN gives 0. Branch-free: adding
/// 1.5 * 2^23 leaves the rounded integer in the low mantissa bits.
#[inline(always)]
#[allow(clippy::manual_clamp)] // `max` first maps NaN to 0; `clamp` would keep it.
pub(crate) fn to_code(v: f32) -> u8 {
    ((v.max(0.0).min(255.0) + 12_582_912.0).to_bits() & 0xff) as u8
}

/// Round to a code of 9 to 16 bits (ties to even), saturating at `max` (at most
/// 65535); NaN gives 0. The same branch-free rounding as [`to_code`].
#[inline(always)]
#[allow(clippy::manual_clamp)] // `max` first maps NaN to 0; `clamp` would keep it.
pub(crate) fn to_code16(v: f32, max: f32) -> u16 {
    ((v.max(0.0).min(max) + 12_582_912.0).to_bits() & 0xffff) as u16
}
