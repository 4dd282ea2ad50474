//! Y'CbCr ↔ RGBA conversion of y4m frames (matrices, ranges, bit depths, chroma
//! siting, up/downsampling of chroma planes); the container is in [`super::y4m`].
//!
//! Files: `samples` (8- and 16-bit sample rows, the code scales of a depth),
//! `to_rgb` and `from_rgb` (the two directions), `resample` (chroma siting filters),
//! `curve` (the vectorised sRGB curve, rounding to codes), `signal` (the other
//! transfers and primaries: PQ, HLG, BT.1886, linear; BT.2020, Display P3).

mod curve;
mod from_rgb;
mod resample;
mod samples;
mod signal;
mod to_rgb;

pub(crate) use curve::*;
pub(crate) use from_rgb::rgba_to_yuv;
pub(crate) use resample::{vertical_down_taps, vertical_up_taps};
pub(crate) use samples::Coeffs;
pub(crate) use to_rgb::yuv_to_rgba;

use super::y4m::*;
use super::{FileFormat, Image, Pixels, SourceInfo};
pub use crate::pixels::color::{Primaries, SignalColor, Transfer};
use std::sync::OnceLock;

/// Y'CbCr matrix coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Matrix {
    /// ITU-R BT.601 (Kr 0.299, Kb 0.114): standard definition.
    Bt601,
    /// ITU-R BT.709 (Kr 0.2126, Kb 0.0722): HD.
    Bt709,
    /// ITU-R BT.2020 non-constant luminance (Kr 0.2627, Kb 0.0593): UHD and HDR
    /// (the transfer and primaries are [`YuvConversion::color`]'s).
    Bt2020,
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
            Matrix::Bt2020 => (0.2627, 0.0593),
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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YuvConversion {
    pub matrix: Matrix,
    pub range: Range,
    pub chroma_fields: ChromaFields,
    /// Clip R'G'B' to [0, 1] (default). When false, colours outside the RGB cube (and
    /// super-whites) survive a Y'CbCr → linear f32 → Y'CbCr trip: the f32 values go below
    /// 0 or above 1 (the sRGB curve extended: linear below 0, power law above 1). The
    /// 8-bit outputs are always clipped.
    pub clip: bool,
    /// What the R'G'B' values are: their transfer and primaries. The default (sRGB,
    /// BT.709) is the fast path; any other is converted to and from the linear
    /// working space (BT.709 primaries, 1.0 = 203 cd/m²) by [`crate::pixels::color`]'s
    /// formulas. PQ and HLG signals are always clipped to their code range.
    pub color: SignalColor,
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
            color: SignalColor::default(),
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
    let color = conv.color;
    let plain = signal::is_plain_srgb(&color);
    let to_working = color.to_working();
    yuv_to_rgba(frame, header, conv, out, 1.0, |row, r, g, b| {
        if plain {
            decode_srgb_planes(clip, [&mut *r, &mut *g, &mut *b]);
        } else {
            signal::decode_row(&color, &to_working, clip, r, g, b);
        }
        for (((px, &r), &g), &b) in row.chunks_exact_mut(4).zip(&*r).zip(&*g).zip(&*b) {
            px.copy_from_slice(&[r, g, b, 1.0]);
        }
    })
}

/// The vectorised sRGB decode of three planar rows, clipped to [0, 1] first or
/// extended past it.
fn decode_srgb_planes(clip: bool, planes: [&mut [f32]; 3]) {
    for plane in planes {
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
}

/// Convert a frame to an [`Image`] of `kind`. The image's [`SourceInfo`] says the
/// stream's depth, opaque, integer; its format is [`FileFormat::Pnm`] (the closest
/// raw-samples format; there is no y4m file format). Above 8 bits, [`RgbKind::SrgbU8`]
/// rounds to 8 bits: [`RgbKind::LinearF32`] keeps the precision. A signal other than
/// sRGB / BT.709 ([`YuvConversion::color`]) always gives [`RgbKind::LinearF32`].
pub fn yuv_to_image(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    kind: RgbKind,
) -> Result<Image, String> {
    let kind = if signal::is_plain_srgb(&conv.color) {
        kind
    } else {
        RgbKind::LinearF32
    };
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
            bit_depth: header.depth,
            has_alpha: false,
            float: false,
        },
    })
}

/// Convert 8-bit RGBA (sRGB-encoded bytes; alpha ignored) into `frame`, resizing its
/// planes to `header` and keeping its `params`. With the default sRGB / BT.709
/// [`YuvConversion::color`] the bytes are the R'G'B' values; with another, they are
/// decoded to linear light and encoded to that signal.
pub fn rgba_u8_to_yuv(
    rgba: &[u8],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
) -> Result<(), String> {
    const INV: f32 = 1.0 / 255.0;
    let color = conv.color;
    let plain = signal::is_plain_srgb(&color);
    let from_working = color.from_working();
    let lut = crate::pixels::srgb::decode_lut_u8();
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            if plain {
                *r = px[0] as f32 * INV;
                *g = px[1] as f32 * INV;
                *b = px[2] as f32 * INV;
            } else {
                *r = lut[px[0] as usize];
                *g = lut[px[1] as usize];
                *b = lut[px[2] as usize];
            }
        }
        if !plain {
            signal::encode_row(&color, &from_working, conv.clip, r, g, b);
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
    let color = conv.color;
    let plain = signal::is_plain_srgb(&color);
    let from_working = color.from_working();
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            (*r, *g, *b) = (px[0], px[1], px[2]);
        }
        if !plain {
            signal::encode_row(&color, &from_working, clip, r, g, b);
            return;
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
