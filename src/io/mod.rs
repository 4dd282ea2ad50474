//! Image files: loading (PNG, JPEG, OpenEXR, TIFF, BMP, TGA, WebP, Radiance HDR, PNM, QOI)
//! into RGBA buffers, and saving them with atomic writes. No GPU code here.
//!
//! Colour conventions:
//! - 8-bit files load as [`Pixels::U8`], the stored (normally sRGB-encoded) bytes as is.
//! - 16-bit PNG/TIFF/PNM load as [`Pixels::F32`] linear light (sRGB-decoded with the exact
//!   formula, or `v / 65535` with [`LoadOptions::assume_linear`]); float TIFF, HDR and EXR
//!   load as stored (linear).
//! - Alpha is never put through the sRGB curve.
//!
//! Every decoder runs behind size limits (32768 px per side, 2^30 pixels) checked before the
//! pixel buffers are allocated, and behind `catch_unwind`, so a damaged file gives
//! [`IoError::Decode`], never a panic or an abort.

mod atomic;
mod convert;
mod decode;
mod encode;
mod exr_io;
mod probe;
pub mod sequence;
pub mod srgb;
pub mod y4m;
pub mod yuv;

use std::fmt;
use std::path::{Path, PathBuf};

use image::{DynamicImage, ImageDecoder, ImageEncoder};

pub use atomic::write_atomic;
use decode::image_error_detail;
pub use decode::{
    decode_image, detect_format, image_dimensions, load_image, load_image_from_memory,
    read_image_file, read_regular_file, MAX_FILE_BYTES,
};
pub use encode::save_image;
pub use probe::image_file_dimensions;

/// Largest accepted width or height.
pub const MAX_SIDE: u32 = 32768;
/// Largest accepted pixel count (width × height).
pub const MAX_PIXELS: u64 = 1 << 30;
/// Memory the `image` decoders may allocate (enough for a 2^30-pixel 8-bit RGBA image).
const MAX_DECODER_ALLOC: u64 = 4 << 30;

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

    /// Bit depth written when [`SaveOptions::bit_depth`] is `None`: 16 (half) for EXR,
    /// 32 for HDR, 8 otherwise.
    pub fn default_bit_depth(self) -> u8 {
        match self {
            FileFormat::Exr => 16,
            FileFormat::Hdr => 32,
            _ => 8,
        }
    }

    fn image_format(self) -> image::ImageFormat {
        match self {
            FileFormat::Png => image::ImageFormat::Png,
            FileFormat::Jpeg => image::ImageFormat::Jpeg,
            FileFormat::Exr => image::ImageFormat::OpenExr,
            FileFormat::Tiff => image::ImageFormat::Tiff,
            FileFormat::Bmp => image::ImageFormat::Bmp,
            FileFormat::Tga => image::ImageFormat::Tga,
            FileFormat::WebP => image::ImageFormat::WebP,
            FileFormat::Hdr => image::ImageFormat::Hdr,
            FileFormat::Pnm => image::ImageFormat::Pnm,
            FileFormat::Qoi => image::ImageFormat::Qoi,
        }
    }

    fn from_image_format(f: image::ImageFormat) -> Option<FileFormat> {
        FileFormat::ALL.into_iter().find(|x| x.image_format() == f)
    }
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Options for [`load_image`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Treat 16-bit integer samples as linear (`v / 65535`) instead of sRGB-encoded.
    pub assume_linear: bool,
}

/// Options for [`save_image`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SaveOptions {
    /// Bits per channel; `None` is the format's [`FileFormat::default_bit_depth`].
    pub bit_depth: Option<u8>,
    /// Write integer files with plain scaling instead of the sRGB curve (and read U8 pixels
    /// as linear when writing float files).
    pub assume_linear: bool,
}

/// Errors of the image file layer. Every message names the path.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    /// File missing / unreadable / unwritable (exit code 2 in the CLI).
    #[error("{}: {source}", shown(path))]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file exists but is not a valid image of its type: corrupt, truncated, unsupported
    /// variant (exit code 1: input rejected).
    #[error("{}: {message}", shown(path))]
    Decode { path: PathBuf, message: String },
    /// The requested output cannot be written in that format (e.g. 16 bits for JPEG, unknown
    /// extension) (exit code 1).
    #[error("{}: {message}", shown(path))]
    Unsupported { path: PathBuf, message: String },
}

/// A path as messages name it; an empty one (an empty argument) says so rather than
/// leaving the message to start with `: `.
fn shown(path: &Path) -> String {
    if path.as_os_str().is_empty() {
        "(empty path)".to_string()
    } else {
        path.display().to_string()
    }
}

impl IoError {
    /// `Decode` or `Unsupported`: the input or the request was rejected (as opposed to a
    /// file system failure).
    pub fn is_input_error(&self) -> bool {
        matches!(self, IoError::Decode { .. } | IoError::Unsupported { .. })
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            IoError::Io { path, .. }
            | IoError::Decode { path, .. }
            | IoError::Unsupported { path, .. } => path,
        }
    }

    fn io(path: &Path, source: std::io::Error) -> IoError {
        IoError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    fn decode(path: &Path, message: impl Into<String>) -> IoError {
        IoError::Decode {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    fn unsupported(path: &Path, message: impl Into<String>) -> IoError {
        IoError::Unsupported {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// Check an image size against [`MAX_SIDE`] and [`MAX_PIXELS`].
pub(crate) fn check_dimensions(width: u64, height: u64) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is empty ({width}x{height})"));
    }
    if width > MAX_SIDE as u64 || height > MAX_SIDE as u64 || width * height > MAX_PIXELS {
        return Err(format!(
            "the image is too large ({width}x{height}; the limit is {MAX_SIDE} pixels per side and {MAX_PIXELS} pixels in all)"
        ));
    }
    Ok(())
}

pub(crate) fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "internal panic".to_string()
    }
}
