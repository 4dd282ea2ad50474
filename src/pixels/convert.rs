//! Pixel conversions between the in-memory RGBA buffers and file sample layouts.
//!
//! Colour channels go through the sRGB curve (unless `assume_linear`); alpha is always
//! a plain linear scale. NaN becomes 0. Large buffers are split over threads.

// The file-layout conversions serve `io`, which is built with the `gpu` feature only.
#![cfg_attr(not(feature = "gpu"), allow(dead_code))]

use super::srgb;
use super::Pixels;

/// Buffers with fewer pixels than this are converted on the calling thread.
const PARALLEL_MIN_PIXELS: usize = 1 << 16;

/// Run `f` over matching runs of whole pixels of `src` (`src_ch` values per pixel) and
/// `dst` (`dst_ch` values per pixel), on several threads for large buffers.
pub(crate) fn par_pixels<S: Sync, D: Send>(
    src: &[S],
    src_ch: usize,
    dst: &mut [D],
    dst_ch: usize,
    f: impl Fn(&[S], &mut [D]) + Sync,
) {
    let n = src.len() / src_ch;
    debug_assert_eq!(dst.len(), n * dst_ch);
    let threads = if n < PARALLEL_MIN_PIXELS {
        1
    } else {
        std::thread::available_parallelism()
            .map(|t| t.get())
            .unwrap_or(1)
            .min(n / (PARALLEL_MIN_PIXELS / 4))
            .max(1)
    };
    if threads == 1 {
        f(src, dst);
        return;
    }
    let per = n.div_ceil(threads);
    std::thread::scope(|s| {
        for (sc, dc) in src.chunks(per * src_ch).zip(dst.chunks_mut(per * dst_ch)) {
            let f = &f;
            s.spawn(move || f(sc, dc));
        }
    });
}

#[inline]
fn unit_to_u8(a: f32) -> u8 {
    // NaN -> 0 (the `as` cast saturates and maps NaN to 0).
    (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[inline]
fn unit_to_u16(a: f32) -> u16 {
    (a.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16
}

#[inline]
fn color_to_u8(c: f32, assume_linear: bool) -> u8 {
    if assume_linear {
        unit_to_u8(c)
    } else {
        srgb::encode_u8(c)
    }
}

#[inline]
fn color_to_u16(c: f32, assume_linear: bool) -> u16 {
    if assume_linear {
        unit_to_u16(c)
    } else {
        srgb::encode_u16(c)
    }
}

/// 8-bit samples with `ch` (3 or 4) channels per pixel.
pub(crate) fn to_u8(pixels: &Pixels, ch: usize, assume_linear: bool) -> Vec<u8> {
    match pixels {
        Pixels::U8(v) if ch == 4 => v.clone(),
        Pixels::U8(v) => {
            let mut out = vec![0u8; v.len() / 4 * ch];
            par_pixels(v, 4, &mut out, ch, |s, d| {
                for (s, d) in s.chunks_exact(4).zip(d.chunks_exact_mut(ch)) {
                    d.copy_from_slice(&s[..ch]);
                }
            });
            out
        }
        Pixels::F32(v) => {
            let mut out = vec![0u8; v.len() / 4 * ch];
            par_pixels(v, 4, &mut out, ch, |s, d| {
                for (s, d) in s.chunks_exact(4).zip(d.chunks_exact_mut(ch)) {
                    d[0] = color_to_u8(s[0], assume_linear);
                    d[1] = color_to_u8(s[1], assume_linear);
                    d[2] = color_to_u8(s[2], assume_linear);
                    if ch == 4 {
                        d[3] = unit_to_u8(s[3]);
                    }
                }
            });
            out
        }
    }
}

/// 16-bit samples, big-endian bytes (as PNG wants them), `ch` (3 or 4) channels per pixel.
pub(crate) fn to_u16_be(pixels: &Pixels, ch: usize, assume_linear: bool) -> Vec<u8> {
    match pixels {
        Pixels::U8(v) => {
            let mut out = vec![0u8; v.len() / 4 * ch * 2];
            par_pixels(v, 4, &mut out, ch * 2, |s, d| {
                for (s, d) in s.chunks_exact(4).zip(d.chunks_exact_mut(ch * 2)) {
                    for c in 0..ch {
                        // value * 257 == the byte repeated
                        d[2 * c] = s[c];
                        d[2 * c + 1] = s[c];
                    }
                }
            });
            out
        }
        Pixels::F32(v) => {
            let mut out = vec![0u8; v.len() / 4 * ch * 2];
            par_pixels(v, 4, &mut out, ch * 2, |s, d| {
                for (s, d) in s.chunks_exact(4).zip(d.chunks_exact_mut(ch * 2)) {
                    for c in 0..3 {
                        let x = color_to_u16(s[c], assume_linear);
                        d[2 * c..2 * c + 2].copy_from_slice(&x.to_be_bytes());
                    }
                    if ch == 4 {
                        d[6..8].copy_from_slice(&unit_to_u16(s[3]).to_be_bytes());
                    }
                }
            });
            out
        }
    }
}

/// 16-bit samples in native order, `ch` (3 or 4) channels per pixel.
pub(crate) fn to_u16(pixels: &Pixels, ch: usize, assume_linear: bool) -> Vec<u16> {
    let be = to_u16_be(pixels, ch, assume_linear);
    be.chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect()
}

/// Linear RGBA floats (NaN replaced by 0). U8 colour channels are sRGB-decoded unless
/// `assume_linear`; alpha is `v / 255`.
pub(crate) fn to_f32_rgba(pixels: &Pixels, assume_linear: bool) -> Vec<f32> {
    match pixels {
        Pixels::F32(v) => {
            if v.iter().any(|x| x.is_nan()) {
                v.iter()
                    .map(|&x| if x.is_nan() { 0.0 } else { x })
                    .collect()
            } else {
                v.clone()
            }
        }
        Pixels::U8(v) => {
            let lut = srgb::decode_lut_u8();
            let mut out = vec![0f32; v.len()];
            par_pixels(v, 4, &mut out, 4, |s, d| {
                for (s, d) in s.chunks_exact(4).zip(d.chunks_exact_mut(4)) {
                    for c in 0..3 {
                        d[c] = if assume_linear {
                            s[c] as f32 / 255.0
                        } else {
                            lut[s[c] as usize]
                        };
                    }
                    d[3] = s[3] as f32 / 255.0;
                }
            });
            out
        }
    }
}

/// Whether every pixel is opaque once written with `bits` per sample.
pub(crate) fn is_opaque(pixels: &Pixels, bits: u8) -> bool {
    match pixels {
        Pixels::U8(v) => v.chunks_exact(4).all(|p| p[3] == 255),
        Pixels::F32(v) => {
            // The smallest alpha that still rounds to the maximum code.
            let min = match bits {
                8 => 254.5 / 255.0,
                16 => 65534.5 / 65535.0,
                _ => 1.0,
            };
            v.chunks_exact(4).all(|p| p[3] >= min)
        }
    }
}

/// Expand 16-bit samples with `ch` channels (1..=4: gray, gray+alpha, RGB, RGBA) to linear
/// RGBA floats.
pub(crate) fn u16_to_f32_rgba(src: &[u16], ch: usize, assume_linear: bool) -> Vec<f32> {
    let lut = srgb::decode_lut_u16();
    let color = |v: u16| {
        if assume_linear {
            v as f32 / 65535.0
        } else {
            lut[v as usize]
        }
    };
    let mut out = vec![0f32; src.len() / ch * 4];
    par_pixels(src, ch, &mut out, 4, |s, d| {
        for (s, d) in s.chunks_exact(ch).zip(d.chunks_exact_mut(4)) {
            let (rgb, a) = match ch {
                1 => ([s[0]; 3], None),
                2 => ([s[0]; 3], Some(s[1])),
                3 => ([s[0], s[1], s[2]], None),
                _ => ([s[0], s[1], s[2]], Some(s[3])),
            };
            d[0] = color(rgb[0]);
            d[1] = color(rgb[1]);
            d[2] = color(rgb[2]);
            d[3] = a.map_or(1.0, |a| a as f32 / 65535.0);
        }
    });
    out
}
