//! Pixels in memory: the plain values every layer may use (an [`Image`], its
//! [`Pixels`], the [`FileFormat`] it came from), and the conversions between 8-bit
//! sRGB codes and linear floats. No files, no GPU: decoding and encoding files is
//! [`crate::io`]'s, uploading and reading textures [`crate::gpu`]'s.

pub mod color;
pub(crate) mod convert;
pub mod srgb;

use std::fmt;
use std::path::Path;

/// Pixel data, always 4 channels RGBA, row-major, tightly packed, top row first.
#[derive(Debug, Clone, PartialEq)]
pub enum Pixels {
    /// 8-bit values exactly as stored in the file (normally sRGB-encoded).
    U8(Vec<u8>),
    /// Linear-light floats (16-bit PNG/TIFF decoded from sRGB to linear unless
    /// `assume_linear`; EXR as stored).
    F32(Vec<f32>),
}

impl Pixels {
    /// Number of samples (4 per pixel).
    pub fn len(&self) -> usize {
        match self {
            Pixels::U8(v) => v.len(),
            Pixels::F32(v) => v.len(),
        }
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Linear-light RGBA floats: F32 as is (NaN → 0), U8 sRGB-decoded (or `v / 255` with
    /// `assume_linear`); alpha is always `v / 255`.
    pub fn to_f32_linear(&self, assume_linear: bool) -> Vec<f32> {
        convert::to_f32_rgba(self, assume_linear)
    }

    /// 8-bit RGBA: U8 as is, F32 clamped to [0, 1] and sRGB-encoded (or scaled with
    /// `assume_linear`), rounded to nearest; alpha scaled.
    pub fn to_u8_srgb(&self, assume_linear: bool) -> Vec<u8> {
        convert::to_u8(self, 4, assume_linear)
    }
}

/// A decoded image.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Pixels,
    pub source: SourceInfo,
}

/// What the file held, before expansion to RGBA.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SourceInfo {
    pub format: FileFormat,
    /// Bits per sample in the file (1, 2, 4, 8, 16 or 32; palette images: index bits).
    pub bit_depth: u8,
    /// Whether the file has an alpha channel (or PNG transparency).
    pub has_alpha: bool,
    /// Whether the samples are floating point (EXR half/float, float TIFF, HDR).
    pub float: bool,
}

/// Image file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FileFormat {
    Png,
    Jpeg,
    Exr,
    Tiff,
    Bmp,
    Tga,
    WebP,
    Hdr,
    Pnm,
    Qoi,
}

impl FileFormat {
    /// All formats.
    pub const ALL: [FileFormat; 10] = [
        FileFormat::Png,
        FileFormat::Jpeg,
        FileFormat::Exr,
        FileFormat::Tiff,
        FileFormat::Bmp,
        FileFormat::Tga,
        FileFormat::WebP,
        FileFormat::Hdr,
        FileFormat::Pnm,
        FileFormat::Qoi,
    ];

    /// The format named by the path's extension (case-insensitive), if known.
    pub fn from_path(p: &Path) -> Option<FileFormat> {
        FileFormat::from_extension(p.extension()?.to_str()?)
    }

    /// The format for a file extension without the dot (case-insensitive).
    pub fn from_extension(ext: &str) -> Option<FileFormat> {
        let ext = ext.to_ascii_lowercase();
        FileFormat::ALL
            .into_iter()
            .find(|f| f.extensions().contains(&ext.as_str()))
    }

    /// Recognised extensions, the usual one first.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            FileFormat::Png => &["png"],
            FileFormat::Jpeg => &["jpg", "jpeg", "jpe", "jfif"],
            FileFormat::Exr => &["exr"],
            FileFormat::Tiff => &["tif", "tiff"],
            FileFormat::Bmp => &["bmp", "dib"],
            FileFormat::Tga => &["tga"],
            FileFormat::WebP => &["webp"],
            FileFormat::Hdr => &["hdr", "rgbe"],
            FileFormat::Pnm => &["ppm", "pnm", "pam", "pgm", "pbm"],
            FileFormat::Qoi => &["qoi"],
        }
    }

    /// A short user-facing name ("PNG", "OpenEXR", ...).
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Png => "PNG",
            FileFormat::Jpeg => "JPEG",
            FileFormat::Exr => "OpenEXR",
            FileFormat::Tiff => "TIFF",
            FileFormat::Bmp => "BMP",
            FileFormat::Tga => "TGA",
            FileFormat::WebP => "WebP",
            FileFormat::Hdr => "Radiance HDR",
            FileFormat::Pnm => "PNM",
            FileFormat::Qoi => "QOI",
        }
    }

    /// Bits per channel this format can be written with: PNG 8/16, JPEG 8, EXR 16 (half) /
    /// 32 (float), TIFF 8/16/32 (float), PNM 8/16, HDR 32, BMP/TGA/WebP/QOI 8.
    pub fn supports_bit_depth(self, bits: u8) -> bool {
        self.bit_depths().contains(&bits)
    }

    /// The bit depths accepted by [`FileFormat::supports_bit_depth`].
    pub fn bit_depths(self) -> &'static [u8] {
        match self {
            FileFormat::Png | FileFormat::Pnm => &[8, 16],
            FileFormat::Exr => &[16, 32],
            FileFormat::Tiff => &[8, 16, 32],
            FileFormat::Hdr => &[32],
            FileFormat::Jpeg
            | FileFormat::Bmp
            | FileFormat::Tga
            | FileFormat::WebP
            | FileFormat::Qoi => &[8],
        }
    }

    /// Bit depth written when `io::SaveOptions::bit_depth` is `None`: 16 (half) for EXR,
    /// 32 for HDR, 8 otherwise.
    pub fn default_bit_depth(self) -> u8 {
        match self {
            FileFormat::Exr => 16,
            FileFormat::Hdr => 32,
            _ => 8,
        }
    }
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
