//! PNG decoding with the checksums checked.
//!
//! The `image` crate's PNG decoder runs the `png` crate with its defaults, which skip
//! the zlib stream's Adler-32 and stop once the image rows are filled: a file whose
//! compressed data was damaged (and whose chunk CRCs were recomputed) decodes to
//! garbage without an error. Here the `png` crate is driven directly with
//! `set_ignore_adler32(false)` (chunk CRCs are checked by default), and the file is
//! read to its `IEND` chunk after the image, so the rest of the file is checked too.
//! PNG's policy (docs/cli.md, "Damaged files"): a wrong CRC or Adler-32, a damaged
//! deflate stream, a file that ends before `IEND`: rejected.
//!
//! The png crate's messages name chunks by their `Debug` form (`ChunkType { type:
//! IDAT, critical: true, ... }`) and deflate errors by their variant names
//! (`WrongChecksum`); [`png_error_text`] writes them as words.

use crate::pixels::color::{Primaries, SignalColor, Transfer};
use image::DynamicImage;
use std::io::Cursor;

/// What a PNG's cICP chunk says (ITU-T H.273 code points), where it says more than
/// sRGB: the signal, and whether it is narrow ("video") range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Cicp {
    pub color: SignalColor,
    pub narrow: bool,
}

/// The signal of H.273 code points; `Err` for code points fxrun does not decode.
fn cicp_signal(c: &png::CodingIndependentCodePoints) -> Result<Cicp, String> {
    let primaries = match c.color_primaries {
        1 | 2 => Primaries::Bt709,
        9 => Primaries::Bt2020,
        12 => Primaries::DisplayP3,
        p => return Err(format!("cICP colour primaries {p}")),
    };
    let transfer = match c.transfer_function {
        13 | 2 => Transfer::Srgb,
        1 | 6 | 14 | 15 => Transfer::Bt1886,
        8 => Transfer::Linear,
        16 => Transfer::Pq,
        18 => Transfer::Hlg,
        t => return Err(format!("cICP transfer {t}")),
    };
    Ok(Cicp {
        color: SignalColor {
            transfer,
            primaries,
            ..SignalColor::default()
        },
        narrow: !c.is_video_full_range_image,
    })
}

/// Decodes a PNG file's (first) image to 8 or 16 bits per sample, with the file's
/// bit depth (8 for a palette) and its cICP signal when it has one that is not
/// sRGB (an unknown one is ignored with a warning: the image is read as sRGB).
pub(super) fn decode_png(
    bytes: &[u8],
    max_alloc: u64,
) -> Result<(DynamicImage, u8, Option<Cicp>), String> {
    let mut options = png::DecodeOptions::default();
    options.set_ignore_adler32(false);
    options.set_ignore_crc(false);
    let mut decoder = png::Decoder::new_with_options(Cursor::new(bytes), options);
    decoder.set_limits(png::Limits {
        bytes: usize::try_from(max_alloc).unwrap_or(usize::MAX),
    });
    let info = decoder.read_header_info().map_err(png_error_text)?;
    super::check_dimensions(u64::from(info.width), u64::from(info.height))?;
    let file_depth = match info.color_type {
        png::ColorType::Indexed => 8,
        _ => info.bit_depth as u8,
    };
    // Palettes to RGB(A), tRNS to alpha, 1/2/4-bit grey to 8 bits.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(png_error_text)?;
    let cicp = reader
        .info()
        .coding_independent_code_points
        .as_ref()
        .and_then(non_srgb_signal);
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| "the image is too large".to_string())?;
    if size as u64 > max_alloc {
        return Err(format!(
            "the image is too large ({size} bytes decoded; the limit is {max_alloc})"
        ));
    }
    let mut buf = vec![0u8; size];
    let frame = reader.next_frame(&mut buf).map_err(png_error_text)?;
    buf.truncate(frame.buffer_size());
    // The rest of the file up to IEND (its chunks' CRCs, the end of the stream).
    reader.finish().map_err(png_error_text)?;
    let img = image_of(&frame, buf)?;
    Ok((img, file_depth, cicp))
}

/// The signal of a cICP chunk, unless it is plain sRGB (full range); an unknown one
/// is ignored with a warning (the image is read as sRGB).
fn non_srgb_signal(c: &png::CodingIndependentCodePoints) -> Option<Cicp> {
    match cicp_signal(c) {
        Ok(s) if s.color.is_srgb() && !s.narrow => None,
        Ok(s) => Some(s),
        Err(what) => {
            log::warn!("PNG with {what}, which fxrun does not decode: read as sRGB");
            None
        }
    }
}

/// The decoded samples `buf` of `frame` as an image of its colour type and depth.
fn image_of(frame: &png::OutputInfo, buf: Vec<u8>) -> Result<DynamicImage, String> {
    let (w, h) = (frame.width, frame.height);
    let wrong_size = || "the decoded data does not match the image size".to_string();
    let img = match (frame.color_type, frame.bit_depth) {
        (png::ColorType::Grayscale, png::BitDepth::Eight) => {
            image::GrayImage::from_raw(w, h, buf).map(DynamicImage::ImageLuma8)
        }
        (png::ColorType::GrayscaleAlpha, png::BitDepth::Eight) => {
            image::GrayAlphaImage::from_raw(w, h, buf).map(DynamicImage::ImageLumaA8)
        }
        (png::ColorType::Rgb, png::BitDepth::Eight) => {
            image::RgbImage::from_raw(w, h, buf).map(DynamicImage::ImageRgb8)
        }
        (png::ColorType::Rgba, png::BitDepth::Eight) => {
            image::RgbaImage::from_raw(w, h, buf).map(DynamicImage::ImageRgba8)
        }
        (color, png::BitDepth::Sixteen) => {
            // PNG stores 16-bit samples big-endian.
            let v: Vec<u16> = buf
                .chunks_exact(2)
                .map(|c| u16::from_be_bytes([c[0], c[1]]))
                .collect();
            match color {
                png::ColorType::Grayscale => {
                    image::ImageBuffer::from_raw(w, h, v).map(DynamicImage::ImageLuma16)
                }
                png::ColorType::GrayscaleAlpha => {
                    image::ImageBuffer::from_raw(w, h, v).map(DynamicImage::ImageLumaA16)
                }
                png::ColorType::Rgb => {
                    image::ImageBuffer::from_raw(w, h, v).map(DynamicImage::ImageRgb16)
                }
                png::ColorType::Rgba => {
                    image::ImageBuffer::from_raw(w, h, v).map(DynamicImage::ImageRgba16)
                }
                png::ColorType::Indexed => None,
            }
        }
        (color, depth) => {
            return Err(format!(
                "unsupported colour type {} at {} bits",
                color_words(color),
                depth as u8
            ))
        }
    };
    img.ok_or_else(wrong_size)
}

fn color_words(c: png::ColorType) -> &'static str {
    match c {
        png::ColorType::Grayscale => "grey",
        png::ColorType::Rgb => "RGB",
        png::ColorType::Indexed => "palette",
        png::ColorType::GrayscaleAlpha => "grey with alpha",
        png::ColorType::Rgba => "RGBA",
    }
}

/// A png crate error in words.
pub(super) fn png_error_text(e: png::DecodingError) -> String {
    match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file is truncated".to_string()
        }
        png::DecodingError::LimitsExceeded => {
            "the image is too large (over the decoder's memory limit)".to_string()
        }
        other => tidy_png_message(&other.to_string()),
    }
}

/// Rewrites the `Debug` forms in a png crate message: `ChunkType { type: IDAT, ... }`
/// becomes `IDAT`, `Corrupt deflate stream. WrongChecksum` becomes `corrupt
/// compressed data (wrong checksum)`, a trailing period is dropped.
pub(crate) fn tidy_png_message(text: &str) -> String {
    let mut s = text.to_string();
    while let Some(i) = s.find("ChunkType { type: ") {
        let name_start = i + "ChunkType { type: ".len();
        let Some(comma) = s[name_start..].find([',', ' ']) else {
            break;
        };
        let name = s[name_start..name_start + comma].to_string();
        let Some(close) = s[name_start..].find('}') else {
            break;
        };
        s.replace_range(i..name_start + close + 1, &name);
    }
    if let Some(i) = s.find("Corrupt deflate stream. ") {
        let what = &s[i + "Corrupt deflate stream. ".len()..];
        let words = camel_to_words(what.trim());
        s = format!("{}corrupt compressed data ({words})", &s[..i]);
    }
    s.trim_end_matches('.').to_string()
}

/// `WrongChecksum` → `wrong checksum`; text that is not one CamelCase word is kept.
fn camel_to_words(s: &str) -> String {
    if s.is_empty() || !s.chars().all(|c| c.is_ascii_alphanumeric()) {
        return s.to_string();
    }
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push(' ');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// Pixels of a PNG whose cICP says another signal than sRGB: the stored samples
/// (`img`, at `depth` bits) as that signal, decoded to linear working-space RGBA
/// floats (alpha as stored).
pub(super) fn decode_cicp(img: &DynamicImage, cicp: &Cicp) -> Vec<f32> {
    let rgba = img.to_rgba32f().into_raw(); // samples / (2^n - 1), no curve
    let depth_max = if matches!(
        img,
        DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_)
            | DynamicImage::ImageRgb16(_)
            | DynamicImage::ImageRgba16(_)
    ) {
        65535.0
    } else {
        255.0
    };
    // Narrow range: code 16 · 2^(n-8) is 0, 235 · 2^(n-8) is 1.
    let scale = (depth_max + 1.0) / 256.0;
    let (off, span) = if cicp.narrow {
        (16.0 * scale / depth_max, 219.0 * scale / depth_max)
    } else {
        (0.0, 1.0)
    };
    let to_working = cicp.color.to_working();
    let mut out = Vec::with_capacity(rgba.len());
    for px in rgba.chunks_exact(4) {
        let s = [px[0], px[1], px[2]].map(|v| ((v - off) / span).clamp(0.0, 1.0));
        let l = cicp.color.decode(s, &to_working);
        out.extend_from_slice(&[l[0], l[1], l[2], px[3]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::tidy_png_message;

    #[test]
    fn debug_forms_become_words() {
        assert_eq!(
            tidy_png_message("CRC error: expected 0x1 have 0x2 while decoding ChunkType { type: IDAT, critical: true, private: false, reserved: false, safecopy: false } chunk."),
            "CRC error: expected 0x1 have 0x2 while decoding IDAT chunk"
        );
        assert_eq!(
            tidy_png_message("Corrupt deflate stream. WrongChecksum"),
            "corrupt compressed data (wrong checksum)"
        );
    }
}
