//! Reading image files: regular files with size caps, format detection, header
//! probes, and decoding behind limits and `crate::unwind::catch_quiet`.

use super::*;
use std::fs::{self, File};
use std::io::Cursor;
use std::path::Path;

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Largest image file read (4 GiB).
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// Read a whole file that must be a regular file (not a device, a pipe or a folder:
/// `/dev/zero` would never end) of at most `max` bytes; both are checked before the
/// contents are read. Those refusals are [`IoError::Decode`] (input rejected).
pub fn read_regular_file(path: &Path, max: u64) -> Result<Vec<u8>, IoError> {
    use std::io::Read as _;
    let not_regular = || {
        IoError::decode(
            path,
            "not a regular file (a device or a pipe cannot be read as an image)",
        )
    };
    let too_big = |len: u64| {
        IoError::decode(
            path,
            format!("the file is too large ({len} bytes; the limit is {max} bytes)"),
        )
    };
    // Checked before opening: opening a FIFO would wait for a writer.
    let meta = fs::metadata(path).map_err(|e| IoError::io(path, e))?;
    if meta.is_dir() {
        return Err(IoError::io(
            path,
            std::io::Error::other("is a folder, not a file"),
        ));
    }
    if !meta.is_file() {
        return Err(not_regular());
    }
    let file = File::open(path).map_err(|e| IoError::io(path, e))?;
    let meta = file.metadata().map_err(|e| IoError::io(path, e))?;
    if !meta.is_file() {
        return Err(not_regular());
    }
    if meta.len() > max {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| IoError::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Load an image file. The format comes from the file's magic bytes, the extension is the
/// fallback (TGA has no magic). Only regular files of at most [`MAX_FILE_BYTES`] are read.
pub fn load_image(path: &Path, opts: &LoadOptions) -> Result<Image, IoError> {
    let bytes = read_regular_file(path, MAX_FILE_BYTES)?;
    decode_bytes(&bytes, path, FileFormat::from_path(path), opts)
}

/// Decode image file bytes read with [`read_image_file`]; `path` names the file in
/// messages and gives the format when the magic bytes say nothing.
pub fn decode_image(bytes: &[u8], path: &Path, opts: &LoadOptions) -> Result<Image, IoError> {
    decode_bytes(bytes, path, FileFormat::from_path(path), opts)
}

/// Read an image file's bytes: a regular file of at most [`MAX_FILE_BYTES`].
pub fn read_image_file(path: &Path) -> Result<Vec<u8>, IoError> {
    read_regular_file(path, MAX_FILE_BYTES)
}

/// An image's width and height from its header alone (no pixel is decoded), checked
/// against [`MAX_SIDE`] and [`MAX_PIXELS`]: so a size a device cannot take is refused
/// before a long decode.
pub fn image_dimensions(bytes: &[u8], path: &Path) -> Result<(u32, u32), IoError> {
    if bytes.is_empty() {
        return Err(IoError::decode(path, "the file is empty"));
    }
    let Some(format) = detect_format(bytes, FileFormat::from_path(path)) else {
        return Err(IoError::decode(path, "not a recognised image file"));
    };
    let invalid =
        |m: String| IoError::decode(path, format!("not a valid {} file: {m}", format.name()));
    let (w, h) = if format == FileFormat::Exr {
        exr_io::exr_dimensions(bytes).map_err(invalid)?
    } else {
        let probe = crate::unwind::catch_quiet(|| {
            let mut reader =
                image::ImageReader::with_format(Cursor::new(bytes), format.image_format());
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(MAX_SIDE);
            limits.max_image_height = Some(MAX_SIDE);
            limits.max_alloc = Some(MAX_DECODER_ALLOC);
            reader.limits(limits);
            reader
                .into_decoder()
                .map(|d| d.dimensions())
                .map_err(image_error_detail)
        });
        match probe {
            Ok(r) => r.map_err(invalid)?,
            Err(p) => return Err(invalid(format!("decoder failure ({p})"))),
        }
    };
    check_dimensions(w as u64, h as u64).map_err(|m| IoError::decode(path, m))?;
    Ok((w, h))
}

/// Decode an image held in memory; `hint` is used when the magic bytes say nothing.
/// Error messages name the file as `<memory>`.
pub fn load_image_from_memory(
    bytes: &[u8],
    hint: Option<FileFormat>,
    opts: &LoadOptions,
) -> Result<Image, IoError> {
    decode_bytes(bytes, Path::new("<memory>"), hint, opts)
}

/// Detect the format of `bytes` from magic bytes, falling back to `hint`.
pub fn detect_format(bytes: &[u8], hint: Option<FileFormat>) -> Option<FileFormat> {
    if bytes.starts_with(&EXR_MAGIC) {
        return Some(FileFormat::Exr);
    }
    match image::guess_format(bytes) {
        Ok(f) => FileFormat::from_image_format(f).or(hint),
        Err(_) => hint,
    }
}

fn decode_bytes(
    bytes: &[u8],
    path: &Path,
    hint: Option<FileFormat>,
    opts: &LoadOptions,
) -> Result<Image, IoError> {
    if bytes.is_empty() {
        return Err(IoError::decode(path, "the file is empty"));
    }
    if !bytes.starts_with(&EXR_MAGIC) {
        if let Ok(f) = image::guess_format(bytes) {
            if FileFormat::from_image_format(f).is_none() {
                return Err(IoError::decode(
                    path,
                    format!(
                        "{} files are not supported",
                        format!("{f:?}").to_uppercase()
                    ),
                ));
            }
        }
    }
    let Some(format) = detect_format(bytes, hint) else {
        return Err(IoError::decode(
            path,
            "not a recognised image file (supported: PNG, JPEG, OpenEXR, TIFF, BMP, TGA, WebP, HDR, PNM, QOI)",
        ));
    };
    if let Some(h) = hint {
        if h != format {
            log::debug!(
                "{}: content is {format} although the name says {h}",
                path.display()
            );
        }
    }
    if format == FileFormat::Exr {
        let px = exr_io::read_exr(bytes)
            .map_err(|m| IoError::decode(path, format!("not a valid OpenEXR file: {m}")))?;
        return Ok(Image {
            width: px.width,
            height: px.height,
            pixels: Pixels::F32(px.rgba),
            source: SourceInfo {
                format,
                bit_depth: px.bit_depth,
                has_alpha: px.has_alpha,
                float: px.float,
            },
        });
    }
    let result = crate::unwind::catch_quiet(|| decode_with_image_crate(bytes, format, opts));
    match result {
        Ok(Ok(img)) => Ok(img),
        Ok(Err(message)) => Err(IoError::decode(
            path,
            format!("not a valid {} file: {message}", format.name()),
        )),
        Err(p) => Err(IoError::decode(
            path,
            format!("not a valid {} file: decoder failure ({p})", format.name()),
        )),
    }
}

pub(super) fn image_error_detail(e: image::ImageError) -> String {
    use std::error::Error as _;
    match e {
        image::ImageError::Decoding(d) => {
            let text = match d.source() {
                Some(s) => s.to_string(),
                None => d.to_string(),
            };
            super::png_decode::tidy_png_message(&text)
        }
        image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file is truncated".to_string()
        }
        image::ImageError::Limits(l) => format!("the image is too large ({l})"),
        image::ImageError::Unsupported(u) => format!("unsupported variant: {u}"),
        other => other.to_string(),
    }
}

fn decode_with_image_crate(
    bytes: &[u8],
    format: FileFormat,
    opts: &LoadOptions,
) -> Result<Image, String> {
    match format {
        FileFormat::Jpeg => super::structure::check_jpeg_structure(bytes)?,
        FileFormat::WebP => super::structure::check_webp_structure(bytes)?,
        _ => {}
    }
    let mut cicp = None;
    let (w, h, img, bit_depth) = if format == FileFormat::Png {
        let (img, depth, c) = super::png_decode::decode_png(bytes, MAX_DECODER_ALLOC)?;
        cicp = c;
        (img.width(), img.height(), img, depth)
    } else {
        let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format.image_format());
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        limits.max_alloc = Some(MAX_DECODER_ALLOC);
        reader.limits(limits);
        let decoder = reader.into_decoder().map_err(image_error_detail)?;
        let (w, h) = decoder.dimensions();
        check_dimensions(w as u64, h as u64)?;
        let original = decoder.original_color_type();
        let img = DynamicImage::from_decoder(decoder).map_err(image_error_detail)?;
        let depth = (original.bits_per_pixel() / original.channel_count().max(1) as u16) as u8;
        (w, h, img, depth)
    };
    if (img.width(), img.height()) != (w, h) {
        return Err(format!(
            "inconsistent image size ({}x{} announced, {}x{} decoded)",
            w,
            h,
            img.width(),
            img.height()
        ));
    }
    let has_alpha = img.color().has_alpha();
    let float = matches!(
        img,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    );
    let lin = opts.assume_linear;
    let pixels = match (img, cicp) {
        // A PNG's cICP (PQ, HLG, BT.2020...): decoded to linear working space.
        (img, Some(c)) if !lin => Pixels::F32(super::png_decode::decode_cicp(&img, &c)),
        (img, _) => plain_pixels(img, lin),
    };
    Ok(Image {
        width: w,
        height: h,
        pixels,
        source: SourceInfo {
            format,
            bit_depth,
            has_alpha,
            float,
        },
    })
}

/// The pixels of a decoded image: 8-bit RGBA as stored, 16 bits sRGB-decoded to
/// floats (or scaled with `lin`), floats as they are.
fn plain_pixels(img: DynamicImage, lin: bool) -> Pixels {
    match img {
        DynamicImage::ImageRgba8(b) => Pixels::U8(b.into_raw()),
        img @ (DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)) => Pixels::U8(img.into_rgba8().into_raw()),
        DynamicImage::ImageLuma16(b) => Pixels::F32(convert::u16_to_f32_rgba(b.as_raw(), 1, lin)),
        DynamicImage::ImageLumaA16(b) => Pixels::F32(convert::u16_to_f32_rgba(b.as_raw(), 2, lin)),
        DynamicImage::ImageRgb16(b) => Pixels::F32(convert::u16_to_f32_rgba(b.as_raw(), 3, lin)),
        DynamicImage::ImageRgba16(b) => Pixels::F32(convert::u16_to_f32_rgba(b.as_raw(), 4, lin)),
        DynamicImage::ImageRgba32F(b) => Pixels::F32(b.into_raw()),
        DynamicImage::ImageRgb32F(b) => {
            let raw = b.into_raw();
            let mut out = Vec::with_capacity(raw.len() / 3 * 4);
            for p in raw.chunks_exact(3) {
                out.extend_from_slice(&[p[0], p[1], p[2], 1.0]);
            }
            Pixels::F32(out)
        }
        other => Pixels::F32(other.into_rgba32f().into_raw()),
    }
}
