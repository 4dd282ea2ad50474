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
//! pixel buffers are allocated, and behind `crate::unwind::catch_quiet`, so a damaged file gives
//! [`IoError::Decode`], never a panic or an abort.

mod atomic;
pub mod color_option;
mod decode;
mod encode;
mod exr_io;
mod png_decode;
mod probe;
pub mod sequence;
mod structure;
pub mod video;
pub mod y4m;
pub mod yuv;

use std::path::{Path, PathBuf};

use image::{DynamicImage, ImageDecoder, ImageEncoder};

use crate::pixels::convert;
pub use crate::pixels::{srgb, FileFormat, Image, Pixels, SourceInfo};
pub use atomic::{create_temporary, rename_into_place, write_atomic, AtomicFile, OutputTarget};
use decode::image_error_detail;
pub use decode::{
    decode_image, detect_format, image_dimensions, load_image, load_image_from_memory,
    read_image_file, read_regular_file, MAX_FILE_BYTES,
};
pub use encode::save_image;
pub(crate) use png_decode::tidy_png_message;
pub use probe::image_file_dimensions;

/// Largest accepted width or height.
pub const MAX_SIDE: u32 = 32768;
/// Largest accepted pixel count (width × height).
pub const MAX_PIXELS: u64 = 1 << 30;
/// Memory the `image` decoders may allocate (enough for a 2^30-pixel 8-bit RGBA image).
const MAX_DECODER_ALLOC: u64 = 4 << 30;

/// The `image` crate's name for each format (the decoders and encoders are the
/// `image` crate's; [`FileFormat`] itself is a plain value in [`crate::pixels`]).
pub(crate) trait ImageCrateFormat: Sized {
    fn image_format(self) -> image::ImageFormat;
    fn from_image_format(f: image::ImageFormat) -> Option<Self>;
}

impl ImageCrateFormat for FileFormat {
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
#[non_exhaustive]
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
