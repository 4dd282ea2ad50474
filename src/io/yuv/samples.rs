//! Samples in planes: one byte each at 8 bits, two bytes little-endian at 9 to 16
//! bits, read into and written from f32 rows; and the code scales of a conversion
//! at a bit depth.

use super::curve::{to_code, to_code16};
use super::{Range, YuvConversion};

/// How a plane stores its samples. The conversions are generic over it, so each
/// depth gets its own vectorised loops.
pub(crate) trait Store: Send + Sync {
    /// Bytes per sample.
    const BYTES: usize;
    /// The samples of a row of bytes, as f32 codes.
    fn samples(row: &[u8]) -> impl Iterator<Item = f32> + '_;
    /// Store f32 codes into a row of bytes: rounded to nearest (ties to even),
    /// saturating to `0..=max`, NaN as 0.
    fn store(values: &[f32], row: &mut [u8], max: f32);
}

/// 8-bit samples.
pub(crate) struct Bytes;

/// 9- to 16-bit samples, little-endian.
pub(crate) struct Words;

impl Store for Bytes {
    const BYTES: usize = 1;
    #[inline(always)]
    fn samples(row: &[u8]) -> impl Iterator<Item = f32> + '_ {
        row.iter().map(|&b| b as f32)
    }
    #[inline(always)]
    fn store(values: &[f32], row: &mut [u8], _max: f32) {
        for (d, &v) in row.iter_mut().zip(values) {
            *d = to_code(v);
        }
    }
}

impl Store for Words {
    const BYTES: usize = 2;
    #[inline(always)]
    fn samples(row: &[u8]) -> impl Iterator<Item = f32> + '_ {
        row.chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as f32)
    }
    #[inline(always)]
    fn store(values: &[f32], row: &mut [u8], max: f32) {
        for (d, &v) in row.chunks_exact_mut(2).zip(values) {
            d.copy_from_slice(&to_code16(v, max).to_le_bytes());
        }
    }
}

/// Scale factors and matrix for one conversion at one bit depth.
#[derive(Clone, Copy)]
pub(crate) struct Coeffs {
    /// Luma code of black and codes per unit.
    pub(crate) y_off: f32,
    pub(crate) y_scale: f32,
    /// Chroma code of zero (Pb = Pr = 0) and codes per unit of Pb / Pr.
    pub(crate) c_mid: f32,
    pub(crate) c_scale: f32,
    /// The largest code, `2^depth - 1`.
    pub(crate) max: f32,
    pub(crate) kr: f32,
    pub(crate) kg: f32,
    pub(crate) kb: f32,
    /// R' = Y' + rv Pr; G' = Y' + gu Pb + gv Pr; B' = Y' + bu Pb.
    pub(crate) rv: f32,
    pub(crate) gu: f32,
    pub(crate) gv: f32,
    pub(crate) bu: f32,
}

impl Coeffs {
    /// The codes of `conv.range` at `depth` bits: limited range is 8-bit's scaled by
    /// 2^(depth - 8) (Y 64-940, Cb/Cr 64-960 at 10 bits); full range is `0..2^depth - 1`
    /// with chroma centred on 2^(depth - 1) (as ffmpeg's swscale converts).
    pub(crate) fn new(conv: &YuvConversion, depth: u8) -> Coeffs {
        let (kr, kb) = conv.matrix.kr_kb();
        let kg = 1.0 - kr - kb;
        let s = (1u32 << (depth - 8)) as f32;
        let max = ((1u32 << depth) - 1) as f32;
        let (y_off, y_scale, c_scale) = match conv.range {
            Range::Limited => (16.0 * s, 219.0 * s, 224.0 * s),
            Range::Full => (0.0, max, max),
        };
        Coeffs {
            y_off,
            y_scale,
            c_mid: 128.0 * s,
            c_scale,
            max,
            kr,
            kg,
            kb,
            rv: 2.0 * (1.0 - kr),
            gu: -2.0 * kb * (1.0 - kb) / kg,
            gv: -2.0 * kr * (1.0 - kr) / kg,
            bu: 2.0 * (1.0 - kb),
        }
    }
}
