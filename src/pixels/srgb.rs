//! The sRGB transfer function (IEC 61966-2-1), exact and fast.
//!
//! The piecewise formula is evaluated in `f64` ("exact"); [`encode_u8`] gives
//! bit-identical results to rounding the exact formula, via a table indexed
//! by the float's exponent and top mantissa bits (one lookup and one compare
//! per value), and [`decode_lut_u8`] / [`decode_lut_u16`] are tables of the
//! exact decode.

use std::sync::OnceLock;

/// sRGB-encoded value (0..1) to linear light, exact formula (evaluated in f64).
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    srgb_to_linear_f64(x as f64) as f32
}

/// Linear light to sRGB-encoded value, exact formula (evaluated in f64).
/// No clamping: values above 1 follow the power curve, negatives the linear segment.
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    linear_to_srgb_f64(x as f64) as f32
}

/// [`srgb_to_linear`] in double precision.
#[inline]
pub fn srgb_to_linear_f64(x: f64) -> f64 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// [`linear_to_srgb`] in double precision.
#[inline]
pub fn linear_to_srgb_f64(x: f64) -> f64 {
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The reference 8-bit encode: `round(255 * linear_to_srgb(clamp(x, 0, 1)))` in f64, NaN -> 0.
/// Slow (one `powf`); [`encode_u8`] returns the same value quickly.
pub fn encode_u8_exact(linear: f32) -> u8 {
    if linear.is_nan() || linear <= 0.0 {
        return 0;
    }
    if linear >= 1.0 {
        return 255;
    }
    (255.0 * linear_to_srgb_f64(linear as f64)).round() as u8
}

/// The 256 linear values of the 8-bit sRGB codes: `decode_lut_u8()[v] == srgb_to_linear(v / 255)`.
pub fn decode_lut_u8() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        let mut t = [0.0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            *v = srgb_to_linear_f64(i as f64 / 255.0) as f32;
        }
        t
    })
}

/// The 65536 linear values of the 16-bit sRGB codes: `decode_lut_u16()[v] == srgb_to_linear(v / 65535)`.
pub fn decode_lut_u16() -> &'static [f32] {
    static LUT: OnceLock<Vec<f32>> = OnceLock::new();
    LUT.get_or_init(|| {
        (0..=u16::MAX as u32)
            .map(|i| srgb_to_linear_f64(i as f64 / 65535.0) as f32)
            .collect()
    })
}

/// Linear light to an 8-bit sRGB code: exactly `round(255 * linear_to_srgb(x))` after clamping
/// `x` to [0, 1] (NaN gives 0). One table lookup and one comparison.
#[inline]
pub fn encode_u8(linear: f32) -> u8 {
    let t = encode_table();
    // Branch-free clamp into [min, 1 - ulp]: `max` maps NaN to `min` (code 0), and the
    // float just below 1.0 already encodes to 255.
    let x = linear.max(t.min).min(BELOW_ONE);
    let idx = ((x.to_bits() - t.min_bits) >> (23 - BUCKET_BITS)) as usize;
    let b = t.buckets[idx];
    b.base + (x >= b.threshold) as u8
}

/// The largest f32 below 1.0.
const BELOW_ONE: f32 = 0.999_999_94;

/// Linear light to a 16-bit sRGB code: `round(65535 * linear_to_srgb(x))` after clamping to
/// [0, 1] (NaN gives 0), exact formula.
#[inline]
pub fn encode_u16(linear: f32) -> u16 {
    if linear.is_nan() || linear <= 0.0 {
        return 0;
    }
    if linear >= 1.0 {
        return u16::MAX;
    }
    (65535.0 * linear_to_srgb_f64(linear as f64)).round() as u16
}

/// Mantissa bits used per octave: 2^8 buckets per power of two, so each bucket spans a relative
/// width of 1/256, and the steepest part of the curve (near 1.0, d(255·srgb)/d(ln x) ≈ 112)
/// moves less than 0.44 codes per bucket: at most one decision threshold falls in a bucket.
const BUCKET_BITS: u32 = 8;

#[derive(Clone, Copy)]
struct Bucket {
    /// Code at the bucket's first float.
    base: u8,
    /// Smallest float giving `base + 1` (infinity when none in reach).
    threshold: f32,
}

struct EncodeTable {
    /// Values at or below this encode to 0 (a power of two below the first threshold).
    min: f32,
    min_bits: u32,
    buckets: Vec<Bucket>,
}

fn encode_table() -> &'static EncodeTable {
    static TABLE: OnceLock<EncodeTable> = OnceLock::new();
    TABLE.get_or_init(build_encode_table)
}

/// Smallest positive f32 `x` in (0, 1] with `encode_u8_exact(x) >= code` (binary search on the
/// bit pattern, which orders positive floats).
fn threshold_for(code: u8) -> f32 {
    let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
    // invariant: exact(lo) < code <= exact(hi)
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if encode_u8_exact(f32::from_bits(mid)) >= code {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    f32::from_bits(hi)
}

fn build_encode_table() -> EncodeTable {
    let mut thresholds = [f32::INFINITY; 257];
    for code in 1..=255u8 {
        thresholds[code as usize] = threshold_for(code);
    }
    // Largest power of two below the first threshold.
    let first = thresholds[1];
    let min_bits = first.to_bits() & !((1u32 << 23) - 1);
    let min = f32::from_bits(min_bits);
    debug_assert!(min < first);
    let n = ((1.0f32.to_bits() - min_bits) >> (23 - BUCKET_BITS)) as usize;
    let buckets = (0..n)
        .map(|i| {
            let start = f32::from_bits(min_bits + ((i as u32) << (23 - BUCKET_BITS)));
            let base = encode_u8_exact(start);
            Bucket {
                base,
                threshold: thresholds[base as usize + 1],
            }
        })
        .collect();
    EncodeTable {
        min,
        min_bits,
        buckets,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_most_one_threshold_per_bucket() {
        let t = encode_table();
        for (i, b) in t.buckets.iter().enumerate() {
            let last = f32::from_bits(t.min_bits + (((i as u32) + 1) << (23 - BUCKET_BITS)) - 1);
            let hi = encode_u8_exact(last);
            assert!(
                hi as u16 <= b.base as u16 + 1,
                "bucket {i} spans {}..{hi}",
                b.base
            );
        }
    }

    #[test]
    fn encode_u8_matches_exact_around_every_threshold() {
        for code in 1..=255u8 {
            let t = threshold_for(code).to_bits();
            for bits in t.saturating_sub(64)..t + 64 {
                let x = f32::from_bits(bits);
                assert_eq!(encode_u8(x), encode_u8_exact(x), "x = {x:e}");
            }
        }
    }

    #[test]
    fn encode_u8_matches_exact_on_a_dense_sweep() {
        // Every 97th float in [2^-16, 1] (about 1.4 million values), plus edges.
        let lo = 2.0f32.powi(-16).to_bits();
        let hi = 1.0f32.to_bits();
        let mut bits = lo;
        while bits <= hi {
            let x = f32::from_bits(bits);
            assert_eq!(encode_u8(x), encode_u8_exact(x), "x = {x:e}");
            bits += 97;
        }
        for x in [
            0.0,
            -0.0,
            -1.0,
            1.0,
            2.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e-30,
        ] {
            assert_eq!(encode_u8(x), encode_u8_exact(x), "x = {x:e}");
        }
    }

    #[test]
    fn decode_then_encode_is_identity() {
        let lut = decode_lut_u8();
        for v in 0..=255u8 {
            assert_eq!(encode_u8(lut[v as usize]), v);
        }
        let lut16 = decode_lut_u16();
        for v in 0..=u16::MAX {
            assert_eq!(encode_u16(lut16[v as usize]), v);
        }
    }
}
