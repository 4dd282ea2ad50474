//! An image file's size from its header, reading only what the decoder needs to find it
//! (not the whole file): so a long list of frames can be checked (all the same size? all
//! within the device's limit?) before any of them is decoded or any output is written.

use std::fs::{self, File};
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::{
    check_dimensions, detect_format, image_dimensions, image_error_detail, read_image_file,
    FileFormat, ImageCrateFormat, IoError,
};

/// The width and height of the image file at `path`, from its header alone (checked against
/// [`super::MAX_SIDE`] and [`super::MAX_PIXELS`] like [`image_dimensions`]). Only regular
/// files are opened. OpenEXR files are read whole (their header reader takes bytes).
///
/// Errors: [`IoError::Io`] when the file cannot be opened or read, [`IoError::Decode`] when
/// it is not a regular file, not an image, or its header is damaged.
pub fn image_file_dimensions(path: &Path) -> Result<(u32, u32), IoError> {
    let meta = fs::metadata(path).map_err(|e| IoError::io(path, e))?;
    if !meta.is_file() {
        return Err(IoError::decode(
            path,
            "not a regular file (a device, a pipe or a folder cannot be read as an image)",
        ));
    }
    let mut file = File::open(path).map_err(|e| IoError::io(path, e))?;
    let mut head = [0u8; 64];
    let mut n = 0;
    while n < head.len() {
        match file.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(IoError::io(path, e)),
        }
    }
    if n == 0 {
        return Err(IoError::decode(path, "the file is empty"));
    }
    let Some(format) = detect_format(&head[..n], FileFormat::from_path(path)) else {
        return Err(IoError::decode(path, "not a recognised image file"));
    };
    if format == FileFormat::Exr {
        return image_dimensions(&read_image_file(path)?, path);
    }
    file.seek(SeekFrom::Start(0))
        .map_err(|e| IoError::io(path, e))?;
    let probe = crate::unwind::catch_quiet(|| {
        let mut reader =
            image::ImageReader::with_format(BufReader::new(file), format.image_format());
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(super::MAX_SIDE);
        limits.max_image_height = Some(super::MAX_SIDE);
        reader.limits(limits);
        reader
            .into_decoder()
            .map(|d| image::ImageDecoder::dimensions(&d))
            .map_err(image_error_detail)
    });
    let (w, h) = match probe {
        Ok(Ok(d)) => d,
        Ok(Err(m)) => {
            return Err(IoError::decode(
                path,
                format!("not a valid {} file: {m}", format.name()),
            ))
        }
        Err(p) => {
            return Err(IoError::decode(
                path,
                format!(
                    "not a valid {} file: decoder failure ({})",
                    format.name(),
                    p
                ),
            ))
        }
    };
    check_dimensions(w as u64, h as u64).map_err(|m| IoError::decode(path, m))?;
    Ok((w, h))
}
