//! Y'CbCr ↔ RGBA conversion of y4m frames (matrices, ranges, chroma siting,
//! up/downsampling of chroma planes); the container is in [`super::y4m`].

use super::y4m::*;
use super::{srgb, FileFormat, Image, Pixels, SourceInfo};
use std::sync::OnceLock;

/// Y'CbCr matrix coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Matrix {
    /// ITU-R BT.601 (Kr 0.299, Kb 0.114): standard definition.
    Bt601,
    /// ITU-R BT.709 (Kr 0.2126, Kb 0.0722): HD.
    Bt709,
}

impl Matrix {
    /// BT.601 up to 576 lines, BT.709 above (what players assume for untagged video).
    pub fn for_height(height: u32) -> Matrix {
        if height <= 576 {
            Matrix::Bt601
        } else {
            Matrix::Bt709
        }
    }

    /// `(Kr, Kb)`.
    pub fn kr_kb(self) -> (f32, f32) {
        match self {
            Matrix::Bt601 => (0.299, 0.114),
            Matrix::Bt709 => (0.2126, 0.0722),
        }
    }
}

/// Y'CbCr quantisation range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Range {
    /// "TV" / "MPEG": Y 16-235, Cb/Cr 16-240 (128 ± 112).
    Limited,
    /// "PC" / "JPEG": Y 0-255, Cb/Cr 128 ± 127.5.
    Full,
}

/// How interlaced 4:2:0 chroma is resampled (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChromaFields {
    /// Per field for `It`/`Ib` streams and `Im` frames whose `I` parameter says so.
    Auto,
    /// Always as a progressive frame.
    Progressive,
    /// Always per field.
    Interlaced,
}

/// How Y'CbCr maps to RGB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct YuvConversion {
    pub matrix: Matrix,
    pub range: Range,
    pub chroma_fields: ChromaFields,
    /// Clip R'G'B' to [0, 1] (default). When false, colours outside the RGB cube (and
    /// super-whites) survive a Y'CbCr → linear f32 → Y'CbCr trip: the f32 values go below
    /// 0 or above 1 (the sRGB curve extended: linear below 0, power law above 1). The
    /// 8-bit outputs are always clipped.
    pub clip: bool,
}

impl YuvConversion {
    /// The defaults for a stream: [`Matrix::for_height`], the range of
    /// [`Y4mHeader::range_hint`] or limited, [`ChromaFields::Auto`], clipping.
    pub fn for_header(header: &Y4mHeader) -> YuvConversion {
        YuvConversion {
            matrix: Matrix::for_height(header.height),
            range: header.range_hint().unwrap_or(Range::Limited),
            chroma_fields: ChromaFields::Auto,
            clip: true,
        }
    }
}

/// Which pixels [`yuv_to_image`] makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RgbKind {
    /// [`Pixels::F32`]: linear light (the R'G'B' values sRGB-decoded), alpha 1.
    LinearF32,
    /// [`Pixels::U8`]: the R'G'B' values as 8-bit (sRGB-encoded) bytes, alpha 255.
    SrgbU8,
}

/// Scale factors and matrix for one conversion.
#[derive(Clone, Copy)]
pub(crate) struct Coeffs {
    /// Luma code of black and codes per unit.
    y_off: f32,
    y_scale: f32,
    /// Chroma codes per unit of Pb / Pr.
    c_scale: f32,
    kr: f32,
    kg: f32,
    kb: f32,
    /// R' = Y' + rv Pr; G' = Y' + gu Pb + gv Pr; B' = Y' + bu Pb.
    rv: f32,
    gu: f32,
    gv: f32,
    bu: f32,
}

impl Coeffs {
    fn new(conv: &YuvConversion) -> Coeffs {
        let (kr, kb) = conv.matrix.kr_kb();
        let kg = 1.0 - kr - kb;
        let (y_off, y_scale, c_scale) = match conv.range {
            Range::Limited => (16.0, 219.0, 224.0),
            Range::Full => (0.0, 255.0, 255.0),
        };
        Coeffs {
            y_off,
            y_scale,
            c_scale,
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

/// A 2-tap linear interpolation: `a[i0] + w * (a[i1] - a[i0])`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tap {
    pub(crate) i0: u32,
    pub(crate) i1: u32,
    pub(crate) w: f32,
}

/// For each luma row, the chroma rows it interpolates between.
pub(crate) fn vertical_up_taps(h: usize, ch: usize, siting: Siting, fields: bool) -> Vec<Tap> {
    let lerp = |p: f32, n: usize| -> (usize, usize, f32) {
        let p = p.clamp(0.0, (n - 1) as f32);
        let i0 = p.floor() as usize;
        let i1 = (i0 + 1).min(n - 1);
        (i0, i1, p - i0 as f32)
    };
    (0..h)
        .map(|y| {
            if siting == Siting::Full {
                return Tap {
                    i0: y as u32,
                    i1: y as u32,
                    w: 0.0,
                };
            }
            if fields {
                let mut f = y & 1;
                // Chroma rows of field f: f, f + 2, ...
                let mut nk = (ch + 1 - f) / 2;
                if nk == 0 {
                    f = 0;
                    nk = ch.div_ceil(2);
                }
                let off = if y & 1 == 0 { 0.25 } else { 0.75 };
                let (k0, k1, w) = lerp(((y / 2) as f32 - off) / 2.0, nk);
                return Tap {
                    i0: (2 * k0 + f) as u32,
                    i1: (2 * k1 + f) as u32,
                    w,
                };
            }
            let p = match siting {
                Siting::Between => (y as f32 - 0.5) / 2.0,
                _ => y as f32 / 2.0,
            };
            let (i0, i1, w) = lerp(p, ch);
            Tap {
                i0: i0 as u32,
                i1: i1 as u32,
                w,
            }
        })
        .collect()
}

/// For each chroma row, up to three (luma row, weight) taps of the downsampling filter.
pub(crate) fn vertical_down_taps(
    h: usize,
    ch: usize,
    siting: Siting,
    fields: bool,
) -> Vec<[(u32, f32); 3]> {
    let last = h - 1;
    (0..ch)
        .map(|c| {
            if siting == Siting::Full {
                return [(c as u32, 1.0), (0, 0.0), (0, 0.0)];
            }
            if fields {
                let (f, k) = (c & 1, c >> 1);
                let r0 = 4 * k + f;
                let r1 = if r0 + 2 <= last { r0 + 2 } else { r0 };
                let (w0, w1) = if f == 0 { (0.75, 0.25) } else { (0.25, 0.75) };
                return [(r0 as u32, w0), (r1 as u32, w1), (0, 0.0)];
            }
            let r = 2 * c;
            match siting {
                Siting::Between => [(r as u32, 0.5), ((r + 1).min(last) as u32, 0.5), (0, 0.0)],
                _ => [
                    (r.saturating_sub(1) as u32, 0.25),
                    (r as u32, 0.5),
                    ((r + 1).min(last) as u32, 0.25),
                ],
            }
        })
        .collect()
}

/// Upsample one chroma row (`src`, chroma width `n`) to luma width (`dst`, `2n - 1` or
/// `2n`): bilinear at the siting's sample positions, edges clamped.
#[inline]
pub(crate) fn upsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = src.len();
    if siting == Siting::Full {
        dst.copy_from_slice(src);
        return;
    }
    // Pairs (2i, 2i+1) for i in 1..n-1 from src[i-1], src[i], src[i+1]; the first and
    // the last pair below.
    if n >= 3 {
        let inner = dst[2..2 * (n - 1)].chunks_exact_mut(2);
        let it = inner.zip(src.iter().zip(&src[1..]).zip(&src[2..]));
        match siting {
            Siting::Between => {
                for (d, ((&p, &c), &nx)) in it {
                    d[0] = 0.75 * c + 0.25 * p;
                    d[1] = 0.75 * c + 0.25 * nx;
                }
            }
            _ => {
                for (d, ((_, &c), &nx)) in it {
                    d[0] = c;
                    d[1] = 0.5 * (c + nx);
                }
            }
        }
    }
    for i in [0, n - 1] {
        let c = src[i];
        let (p, nx) = (src[i.saturating_sub(1)], src[(i + 1).min(n - 1)]);
        let (even, odd) = match siting {
            Siting::Between => (0.75 * c + 0.25 * p, 0.75 * c + 0.25 * nx),
            _ => (c, 0.5 * (c + nx)),
        };
        dst[2 * i] = even;
        if let Some(o) = dst.get_mut(2 * i + 1) {
            *o = odd;
        }
    }
}

/// Downsample one full-width row (`src`) to chroma width (`dst`): a 2-tap box for
/// chroma between columns, [1 2 1]/4 for co-sited chroma, edges clamped.
#[inline]
pub(crate) fn downsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = dst.len();
    let last = src.len() - 1;
    match siting {
        Siting::Full => dst.copy_from_slice(src),
        Siting::Between => {
            for (d, pair) in dst.iter_mut().zip(src.chunks_exact(2)) {
                *d = 0.5 * (pair[0] + pair[1]);
            }
            if src.len() % 2 == 1 {
                dst[n - 1] = src[last];
            }
        }
        Siting::CoSited => {
            dst[0] = 0.75 * src[0] + 0.25 * src[1.min(last)];
            if n >= 2 {
                // dst[i] from src[2i-1], src[2i], src[2i+1] for i in 1..
                // (the last one clamped when the width is odd: src[2i+1] missing).
                let pairs = src[1..].chunks_exact(2).zip(src[2..].chunks(2));
                for (d, (ab, next)) in dst[1..].iter_mut().zip(pairs) {
                    let (a, b) = (ab[0], ab[1]);
                    let c = next.get(1).copied().unwrap_or(b);
                    *d = 0.25 * a + 0.5 * b + 0.25 * c;
                }
            }
        }
    }
}

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
    let lin = x * (1.0 / 12.92);
    let v = if x <= 0.04045 { lin } else { p };
    // Exactly 1 at 1 (the polynomial is 1.2e-6 short).
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
    let lin = x * 12.92;
    let v = if x <= 0.003_130_8 { lin } else { p };
    if x >= 1.0 {
        1.0
    } else {
        v
    }
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

/// Threads for a job of `pixels` pixels over `rows` rows.
pub(crate) fn threads_for(pixels: usize, rows: usize) -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    if pixels < 1 << 16 {
        return 1;
    }
    let cores = *CORES.get_or_init(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    cores.min(pixels >> 15).min(rows.max(1)).max(1)
}

/// Check that a frame and an RGBA buffer of `len` samples fit `header`.
pub(crate) fn check_rgba(header: &Y4mHeader, len: usize) -> Result<(), String> {
    header.validate()?;
    let want = header.width as usize * header.height as usize * 4;
    if len != want {
        return Err(format!(
            "{len} RGBA samples given for a {}x{} frame ({want} expected)",
            header.width, header.height
        ));
    }
    Ok(())
}

/// Convert a frame to RGBA pixels of any type. For each output row,
/// `emit(out_row, r, g, b)` stores the row from its R'G'B' values (unclipped, scaled by
/// `scale`: 1.0 is the unit range), given as three planar rows (structure of arrays, so
/// that the per-pixel arithmetic vectorises; `emit` may overwrite them).
pub(crate) fn yuv_to_rgba<T: Send>(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [T],
    scale: f32,
    emit: impl Fn(&mut [T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, out.len())?;
    frame.check_size(header)?;
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv);
    // Y' = (Y - y_off) * ys; Pb = (Cb - 128) * cs, both times `scale`.
    let ys = scale / k.y_scale;
    let y0s = -k.y_off * ys;
    let cs = scale / k.c_scale;
    let vtaps = if chroma.has_chroma() {
        vertical_up_taps(
            h,
            ch,
            chroma.vertical_siting(),
            frame.field_chroma(header, conv),
        )
    } else {
        Vec::new()
    };
    let hsiting = chroma.horizontal_siting();
    let threads = threads_for(w * h, h);
    let band = h.div_ceil(threads);
    let work = |y0: usize, out: &mut [T]| {
        let mut cu = vec![0f32; cw];
        let mut cv = vec![0f32; cw];
        let mut fu = vec![0f32; w];
        let mut fv = vec![0f32; w];
        let mut rr = vec![0f32; w];
        let mut gg = vec![0f32; w];
        let mut bb = vec![0f32; w];
        for (dy, orow) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = y0 + dy;
            let yrow = &frame.y[y * w..(y + 1) * w];
            if !chroma.has_chroma() {
                for (d, &l) in rr.iter_mut().zip(yrow) {
                    *d = l as f32 * ys + y0s;
                }
                gg.copy_from_slice(&rr);
                bb.copy_from_slice(&rr);
                emit(orow, &mut rr, &mut gg, &mut bb);
                continue;
            }
            let t = vtaps[y];
            for (plane, crow) in [(&frame.u, &mut cu), (&frame.v, &mut cv)] {
                let r0 = &plane[t.i0 as usize * cw..][..cw];
                let r1 = &plane[t.i1 as usize * cw..][..cw];
                let (w0, w1) = ((1.0 - t.w) * cs, t.w * cs);
                for ((d, &a), &b) in crow.iter_mut().zip(r0).zip(r1) {
                    *d = a as f32 * w0 + b as f32 * w1 - 128.0 * cs;
                }
            }
            upsample_row(&cu, &mut fu, hsiting);
            upsample_row(&cv, &mut fv, hsiting);
            for (((((r, g), b), &l), &pb), &pr) in rr
                .iter_mut()
                .zip(gg.iter_mut())
                .zip(bb.iter_mut())
                .zip(yrow)
                .zip(&fu)
                .zip(&fv)
            {
                let yv = l as f32 * ys + y0s;
                *r = yv + k.rv * pr;
                *g = yv + k.gu * pb + k.gv * pr;
                *b = yv + k.bu * pb;
            }
            emit(orow, &mut rr, &mut gg, &mut bb);
        }
    };
    if threads == 1 {
        work(0, out);
    } else {
        std::thread::scope(|s| {
            for (i, chunk) in out.chunks_mut(band * w * 4).enumerate() {
                let work = &work;
                s.spawn(move || work(i * band, chunk));
            }
        });
    }
    Ok(())
}

/// Convert a frame to 8-bit RGBA (the R'G'B' values, clipped and rounded; alpha 255).
/// `out` must hold `width * height * 4` bytes.
pub fn yuv_to_rgba_u8(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [u8],
) -> Result<(), String> {
    yuv_to_rgba(frame, header, conv, out, 255.0, |row, r, g, b| {
        for (((px, &r), &g), &b) in row.chunks_exact_mut(4).zip(&*r).zip(&*g).zip(&*b) {
            let rgba = u32::from_le_bytes([to_code(r), to_code(g), to_code(b), 255]);
            px.copy_from_slice(&rgba.to_le_bytes());
        }
    })
}

/// Convert a frame to linear-light RGBA floats (R'G'B' sRGB-decoded; alpha 1). Clipped to
/// [0, 1] unless `conv.clip` is false. `out` must hold `width * height * 4` floats.
pub fn yuv_to_rgba_f32(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [f32],
) -> Result<(), String> {
    let clip = conv.clip;
    yuv_to_rgba(frame, header, conv, out, 1.0, |row, r, g, b| {
        for plane in [&mut *r, &mut *g, &mut *b] {
            if clip {
                for v in plane.iter_mut() {
                    *v = srgb_decode_unit(v.clamp(0.0, 1.0));
                }
            } else {
                for v in plane.iter_mut() {
                    *v = srgb_decode(*v);
                }
            }
        }
        for (((px, &r), &g), &b) in row.chunks_exact_mut(4).zip(&*r).zip(&*g).zip(&*b) {
            px.copy_from_slice(&[r, g, b, 1.0]);
        }
    })
}

/// Convert a frame to an [`Image`] of `kind`. The image's [`SourceInfo`] says 8-bit,
/// opaque, integer; its format is [`FileFormat::Pnm`] (the closest raw-samples format;
/// there is no y4m file format).
pub fn yuv_to_image(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    kind: RgbKind,
) -> Result<Image, String> {
    check_rgba(header, header.width as usize * header.height as usize * 4)?;
    let n = header.width as usize * header.height as usize * 4;
    let pixels = match kind {
        RgbKind::SrgbU8 => {
            let mut out = vec![0u8; n];
            yuv_to_rgba_u8(frame, header, conv, &mut out)?;
            Pixels::U8(out)
        }
        RgbKind::LinearF32 => {
            let mut out = vec![0f32; n];
            yuv_to_rgba_f32(frame, header, conv, &mut out)?;
            Pixels::F32(out)
        }
    };
    Ok(Image {
        width: header.width,
        height: header.height,
        pixels,
        source: SourceInfo {
            format: FileFormat::Pnm,
            bit_depth: 8,
            has_alpha: false,
            float: false,
        },
    })
}

/// Convert RGBA pixels of any type to a frame: `load(in_row, r, g, b)` stores the R'G'B'
/// values of one input row into three planar rows (alpha is ignored). `frame.params` are kept (they decide
/// the chroma fields of `Im` streams).
pub(crate) fn rgba_to_yuv<T: Sync>(
    rgba: &[T],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
    load: impl Fn(&[T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, rgba.len())?;
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv);
    frame.y.resize(w * h, 0);
    frame.u.resize(cw * ch, 0);
    frame.v.resize(cw * ch, 0);
    let fields = frame.field_chroma(header, conv);
    let hsiting = chroma.horizontal_siting();
    let threads = threads_for(w * h, h);
    // Y' code = y_off + y_scale * Y'; chroma code = 128 + c_scale * P.
    let (ky_r, ky_g, ky_b) = (k.y_scale * k.kr, k.y_scale * k.kg, k.y_scale * k.kb);
    let (pb_s, pr_s) = (0.5 / (1.0 - k.kb), 0.5 / (1.0 - k.kr));
    // Pass 1: luma, and Pb / Pr (in code units, without the 128 offset) of every row,
    // downsampled across to chroma width.
    let mut pb = vec![0f32; if chroma.has_chroma() { cw * h } else { 0 }];
    let mut pr = vec![0f32; pb.len()];
    {
        let band = h.div_ceil(threads);
        let pass1 = |y0: usize, yout: &mut [u8], pbo: &mut [f32], pro: &mut [f32]| {
            let mut rr = vec![0f32; w];
            let mut gg = vec![0f32; w];
            let mut bb = vec![0f32; w];
            for (dy, yrow) in yout.chunks_exact_mut(w).enumerate() {
                let y = y0 + dy;
                load(&rgba[y * w * 4..(y + 1) * w * 4], &mut rr, &mut gg, &mut bb);
                if !chroma.has_chroma() {
                    for (((d, &r), &g), &b) in yrow.iter_mut().zip(&rr).zip(&gg).zip(&bb) {
                        *d = to_code(k.y_off + ky_r * r + ky_g * g + ky_b * b);
                    }
                    continue;
                }
                // Y' into the luma row; Pb and Pr in place of B' and R'.
                for ((d, r), (g, b)) in yrow
                    .iter_mut()
                    .zip(rr.iter_mut())
                    .zip(gg.iter().zip(bb.iter_mut()))
                {
                    let yl = k.kr * *r + k.kg * *g + k.kb * *b;
                    *d = to_code(k.y_off + k.y_scale * yl);
                    *b = k.c_scale * pb_s * (*b - yl);
                    *r = k.c_scale * pr_s * (*r - yl);
                }
                downsample_row(&bb, &mut pbo[dy * cw..(dy + 1) * cw], hsiting);
                downsample_row(&rr, &mut pro[dy * cw..(dy + 1) * cw], hsiting);
            }
        };
        if threads == 1 {
            pass1(0, &mut frame.y, &mut pb, &mut pr);
        } else {
            std::thread::scope(|s| {
                let cband = if chroma.has_chroma() { band * cw } else { 1 };
                let mut pbc = pb.chunks_mut(cband);
                let mut prc = pr.chunks_mut(cband);
                for (i, yc) in frame.y.chunks_mut(band * w).enumerate() {
                    let pbo = pbc.next().unwrap_or_default();
                    let pro = prc.next().unwrap_or_default();
                    let pass1 = &pass1;
                    s.spawn(move || pass1(i * band, yc, pbo, pro));
                }
            });
        }
    }
    if !chroma.has_chroma() {
        return Ok(());
    }
    // Pass 2: vertical downsampling into the chroma planes.
    let taps = vertical_down_taps(h, ch, chroma.vertical_siting(), fields);
    let band = ch.div_ceil(threads);
    let pass2 = |c0: usize, uo: &mut [u8], vo: &mut [u8]| {
        for (dc, (urow, vrow)) in uo
            .chunks_exact_mut(cw)
            .zip(vo.chunks_exact_mut(cw))
            .enumerate()
        {
            let t = taps[c0 + dc];
            for (src, dst) in [(&pb, urow), (&pr, vrow)] {
                let r0 = &src[t[0].0 as usize * cw..][..cw];
                let r1 = &src[t[1].0 as usize * cw..][..cw];
                let r2 = &src[t[2].0 as usize * cw..][..cw];
                let (w0, w1, w2) = (t[0].1, t[1].1, t[2].1);
                for (d, ((&a, &b), &c)) in dst.iter_mut().zip(r0.iter().zip(r1).zip(r2)) {
                    *d = to_code(128.0 + w0 * a + w1 * b + w2 * c);
                }
            }
        }
    };
    if threads == 1 {
        pass2(0, &mut frame.u, &mut frame.v);
    } else {
        std::thread::scope(|s| {
            for (i, (uc, vc)) in frame
                .u
                .chunks_mut(band * cw)
                .zip(frame.v.chunks_mut(band * cw))
                .enumerate()
            {
                let pass2 = &pass2;
                s.spawn(move || pass2(i * band, uc, vc));
            }
        });
    }
    Ok(())
}

/// Convert 8-bit RGBA (sRGB-encoded R'G'B' bytes; alpha ignored) into `frame`, resizing its
/// planes to `header` and keeping its `params`.
pub fn rgba_u8_to_yuv(
    rgba: &[u8],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
) -> Result<(), String> {
    const INV: f32 = 1.0 / 255.0;
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            *r = px[0] as f32 * INV;
            *g = px[1] as f32 * INV;
            *b = px[2] as f32 * INV;
        }
    })
}

/// Convert linear-light RGBA floats (sRGB-encoded to R'G'B'; clipped to [0, 1] first
/// unless `conv.clip` is false; alpha ignored) into `frame`, resizing its planes to
/// `header` and keeping its `params`. NaN counts as 0.
pub fn rgba_f32_to_yuv(
    rgba: &[f32],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
) -> Result<(), String> {
    let clip = conv.clip;
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            (*r, *g, *b) = (px[0], px[1], px[2]);
        }
        for plane in [r, g, b] {
            if clip {
                for v in plane.iter_mut() {
                    // `max` first: NaN becomes 0 (`clamp` would keep it).
                    #[allow(clippy::manual_clamp)]
                    let c = v.max(0.0).min(1.0);
                    *v = srgb_encode_unit(c);
                }
            } else {
                for v in plane.iter_mut() {
                    *v = srgb_encode(*v);
                }
            }
        }
    })
}

/// Convert an [`Image`] (U8: sRGB bytes; F32: linear light) to a new frame for `header`
/// (whose size must match the image's). The frame has no `FRAME` parameters.
pub fn image_to_yuv(
    image: &Image,
    header: &Y4mHeader,
    conv: &YuvConversion,
) -> Result<YuvFrame, String> {
    if image.width != header.width || image.height != header.height {
        return Err(format!(
            "the image is {}x{} but the y4m stream is {}x{}",
            image.width, image.height, header.width, header.height
        ));
    }
    let mut frame = YuvFrame::default();
    match &image.pixels {
        Pixels::U8(v) => rgba_u8_to_yuv(v, header, conv, &mut frame)?,
        Pixels::F32(v) => rgba_f32_to_yuv(v, header, conv, &mut frame)?,
    }
    Ok(frame)
}
