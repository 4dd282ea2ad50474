//! YUV4MPEG2 (`.y4m`, `ffmpeg -f yuv4mpegpipe`) streams: a reader, a writer, and the
//! conversions between Y'CbCr frames (8 to 16 bits) and RGBA [`Image`]s.
//!
//! # Format
//!
//! A stream is one header line, `YUV4MPEG2` followed by space-separated fields and `\n`:
//!
//! | field | meaning | here |
//! |---|---|---|
//! | `W<w>` `H<h>` | size (required) | 1 to [`MAX_SIDE`] each |
//! | `F<n>:<d>` | frame rate | [`Y4mHeader::fps`]; `0:0` (also when absent) = unknown |
//! | `I<p\|t\|b\|m\|?>` | progressive, top / bottom field first, mixed (per frame), unknown | [`Interlace`] |
//! | `A<n>:<d>` | pixel aspect ratio | [`Y4mHeader::aspect`]; `0:0` (also when absent) = unknown |
//! | `C<name>` | sample layout and depth | [`Chroma`] and [`Y4mHeader::depth`]; `420jpeg` when absent |
//! | `X<text>` | extensions (`XCOLORRANGE=FULL`, `XYSCSS=420MPEG2`, ...) | [`Y4mHeader::extra`], passed through |
//!
//! Unknown fields are ignored. Each frame is a line `FRAME` (optionally followed by
//! space-separated parameters, kept in [`YuvFrame::params`]) and the planes Y, Cb, Cr
//! (only Y for `Cmono`), rows top to bottom without padding. Chroma planes of 4:2:0 are
//! `ceil(w/2) x ceil(h/2)`, of 4:2:2 `ceil(w/2) x h`.
//!
//! Samples are 8 bits (one byte) for `C420jpeg`, `C420mpeg2`, `C420paldv`, `C420`,
//! `C422`, `C444`, `Cmono`; the layouts ffmpeg writes for 9 to 16 bits
//! (`-pix_fmt yuv420p10le -strict -1 -f yuv4mpegpipe`) store each sample in two bytes,
//! little-endian: `C420p9`, `C420p10`, `C420p12`, `C420p14`, `C420p16` (4:2:0, chroma
//! centred as in `420jpeg`), the same for `C422pN` and `C444pN`, and `Cmono9`,
//! `Cmono10`, `Cmono12`, `Cmono16`. The depth is [`Y4mHeader::depth`].
//!
//! Frame numbers in messages count from 0 (the first frame of the stream is frame 0), and
//! say so: `stdin: y4m frame 12 (0-based): truncated (got 1000 of 622080 bytes)`.
//!
//! Limits: [`MAX_SIDE`] per side, header lines up to [`MAX_HEADER_BYTES`] and frame lines
//! up to [`MAX_FRAME_LINE_BYTES`]. A frame's buffers grow as its bytes arrive (in steps of
//! at most 16 MiB), so a header announcing a huge size allocates nothing a truncated
//! stream does not deliver.
//!
//! # Colour
//!
//! [`YuvConversion`] says how Y'CbCr maps to R'G'B': [`Matrix::Bt601`] or
//! [`Matrix::Bt709`] (or [`Matrix::Bt2020`], set by the caller), [`Range::Limited`]
//! (Y 16-235, Cb/Cr 16-240) or [`Range::Full`] (0-255, chroma scaled by 255 as in JPEG);
//! at n bits the codes are those of 8 bits times 2^(n-8) in limited range (Y 64-940 at
//! 10 bits) and `0..2^n - 1` in full range (chroma centred on 2^(n-1), scaled by
//! 2^n - 1), as ffmpeg converts them. [`YuvConversion::for_header`] picks BT.601 for
//! heights up to 576 and BT.709 above, and limited range unless the header says
//! `XCOLORRANGE=FULL` (ffmpeg writes that extension when it knows the range). By default
//! ([`YuvConversion::color`]: sRGB, BT.709; PQ, HLG, BT.1886, BT.2020 and Display P3 are
//! the other signals, converted to linear BT.709 at 1.0 = 203 cd/m²) the R'G'B'
//! values are treated as sRGB-encoded, the same convention as 8-bit image files, so a
//! y4m → PNG → y4m trip is consistent: [`RgbKind::SrgbU8`] gives the R'G'B' bytes and
//! [`RgbKind::LinearF32`] their sRGB decode to linear light (what streams above 8 bits
//! are read as, so that no precision is lost before the GPU).
//!
//! # Chroma siting
//!
//! Chroma is upsampled bilinearly from the sample positions of the layout and downsampled
//! with the matching filter at those positions:
//!
//! | layout | horizontal | vertical | downsampling |
//! |---|---|---|---|
//! | `420jpeg`, `420` | between luma columns | between luma rows | 2x2 box |
//! | `420mpeg2` | on even luma columns | between luma rows | [1 2 1]/4 across, box down |
//! | `420paldv` | on even luma columns | on even luma rows | [1 2 1]/4 both ways |
//! | `422` | on even luma columns | — | [1 2 1]/4 across |
//! | `444`, `mono` | — | — | — |
//!
//! `420paldv` really has Cr on the top-field lines and Cb on the bottom-field ones; like
//! ffmpeg, it is treated as "top-left" (co-sited on even rows and columns).
//!
//! Interlaced 4:2:0 (`It`/`Ib`, or a `FRAME Ixyz` parameter with `z` = `i` in an `Im`
//! stream) stores each field's chroma in alternate chroma rows: chroma row `2k + f`
//! belongs to field `f` and sits between that field's lines (top field: a quarter of the
//! way, bottom field: three quarters). With [`ChromaFields::Auto`] such frames are
//! resampled within each field (no chroma mixing across fields, which a deinterlacer needs):
//! upsampling interpolates between the field's chroma rows, downsampling weights the two
//! field lines around each chroma row 3:1 (top field) or 1:3 (bottom field). This applies
//! to `420jpeg`, `420mpeg2` and `420` (not `420paldv`). At the picture edges the nearest
//! chroma sample is repeated. ffmpeg's default RGB conversion ignores interlacing (and
//! replicates chroma); its `scale=interl=1` does the same as here (see the tests).
//!
//! # Speed
//!
//! The conversions are branch-free per-row f32 loops over planar rows, which the compiler
//! vectorises, without allocation per pixel (a few row buffers per thread), split over
//! threads by row bands for frames of 65536 pixels or more. The sRGB curve is a fitted
//! polynomial (error below 4e-6, exact linear segment near black). For the GPU pipeline
//! [`RgbKind::SrgbU8`] is the cheaper choice: 8-bit sRGB textures are decoded by the GPU.
//!
//! Files: `header` (the header line and its fields), `frame` (a frame's planes),
//! `reader`, `writer`; the colour conversions are in [`super::yuv`].

use std::io;

use super::IoError;

mod frame;
mod header;
mod reader;
mod writer;

pub use frame::YuvFrame;
use header::escape;
pub use header::{Chroma, Interlace, Siting, Y4mHeader};
pub use reader::Y4mReader;
pub use writer::Y4mWriter;

/// Largest accepted width or height.
pub const MAX_SIDE: u32 = 16384;
/// Longest accepted header line, newline included.
pub const MAX_HEADER_BYTES: usize = 4096;
/// Longest accepted `FRAME` line, newline included.
pub const MAX_FRAME_LINE_BYTES: usize = 1024;
/// ffmpeg's demuxer (up to at least 7.x) reads header lines of at most 96 bytes; the
/// writer logs a warning above that.
const FFMPEG_MAX_HEADER: usize = 96;

const MAGIC: &[u8] = b"YUV4MPEG2";
const FRAME_MAGIC: &[u8] = b"FRAME";
/// Largest step a frame buffer grows by before its data has arrived.
const READ_CHUNK: usize = 16 << 20;

/// Errors of the YUV4MPEG2 reader and writer. Every message starts with the stream's name
/// (`stdin`, a file name); frame numbers count from 0.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Y4mError {
    /// The header line is missing, malformed, out of limits or unsupported.
    #[error("{name}: y4m header: {message}")]
    Header { name: String, message: String },
    /// A frame is malformed or truncated (reading), or does not fit the header (writing).
    #[error("{name}: y4m frame {frame} (0-based): {message}")]
    Frame {
        name: String,
        frame: u64,
        message: String,
    },
    /// Reading or writing failed (other than a truncated stream).
    #[error("{name}: {context}: {source}")]
    Io {
        name: String,
        context: String,
        source: io::Error,
    },
}

impl Y4mError {
    /// The stream's name.
    pub fn name(&self) -> &str {
        match self {
            Y4mError::Header { name, .. }
            | Y4mError::Frame { name, .. }
            | Y4mError::Io { name, .. } => name,
        }
    }

    /// The frame (0-based) the error is about, if any.
    pub fn frame(&self) -> Option<u64> {
        match self {
            Y4mError::Frame { frame, .. } => Some(*frame),
            _ => None,
        }
    }
}

impl From<Y4mError> for IoError {
    /// [`Y4mError::Io`] becomes [`IoError::Io`], the others [`IoError::Decode`] (input
    /// rejected), with the stream's name as the path and the same message.
    fn from(e: Y4mError) -> IoError {
        match e {
            Y4mError::Io {
                name,
                context,
                source,
            } => IoError::Io {
                path: name.into(),
                source: io::Error::new(source.kind(), format!("{context}: {source}")),
            },
            Y4mError::Header { name, message } => IoError::Decode {
                path: name.into(),
                message: format!("y4m header: {message}"),
            },
            Y4mError::Frame {
                name,
                frame,
                message,
            } => IoError::Decode {
                path: name.into(),
                message: format!("y4m frame {frame} (0-based): {message}"),
            },
        }
    }
}

pub use super::yuv::*;

#[cfg(test)]
mod tests {
    use super::super::srgb;
    use super::*;

    #[test]
    fn srgb_curves_are_accurate() {
        let mut worst_d = 0f64;
        let mut worst_e = 0f64;
        for i in 0..=1_000_000 {
            let x = i as f32 / 1_000_000.0;
            let exact_d = srgb::srgb_to_linear_f64(x as f64);
            let exact_e = srgb::linear_to_srgb_f64(x as f64);
            worst_d = worst_d.max((srgb_decode(x) as f64 - exact_d).abs());
            worst_e = worst_e.max((srgb_encode(x) as f64 - exact_e).abs());
        }
        assert!(worst_d < 3e-6, "decode error {worst_d:e}");
        assert!(worst_e < 4e-6, "encode error {worst_e:e}");
        assert_eq!(srgb_decode(0.0), 0.0);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert_eq!(srgb_decode(1.0), 1.0);
        assert_eq!(srgb_encode(1.0), 1.0);
        assert!((srgb_decode(1.5) - srgb::srgb_to_linear(1.5)).abs() < 1e-6);
        assert!((srgb_decode(-0.5) + 0.5 / 12.92).abs() < 1e-7);
        assert!((srgb_encode(-0.5) + 0.5 * 12.92).abs() < 1e-6);
        // Every 8-bit code survives decode, encode and rounding.
        for v in 0..=255u8 {
            let back = srgb_encode_unit(srgb_decode_unit(v as f32 / 255.0)) * 255.0;
            assert_eq!(to_code(back), v);
        }
    }

    #[test]
    fn rounding_to_codes() {
        assert_eq!(to_code(-3.0), 0);
        assert_eq!(to_code(0.49), 0);
        assert_eq!(to_code(0.51), 1);
        assert_eq!(to_code(254.6), 255);
        assert_eq!(to_code(1e9), 255);
        assert_eq!(to_code(f32::NAN), 0);
        assert_eq!(to_code(f32::INFINITY), 255);
        assert_eq!(to_code(f32::NEG_INFINITY), 0);
        for v in 0..=255u8 {
            assert_eq!(to_code(v as f32), v);
        }
    }

    #[test]
    fn field_taps_stay_in_their_field() {
        for h in [1usize, 2, 3, 4, 5, 8, 9, 576] {
            let ch = h.div_ceil(2);
            for (y, t) in vertical_up_taps(h, ch, Siting::Between, true)
                .iter()
                .enumerate()
            {
                assert!((t.i0 as usize) < ch && (t.i1 as usize) < ch, "h {h} y {y}");
                if ch >= 2 {
                    assert_eq!(t.i0 as usize & 1, y & 1, "h {h} y {y}");
                    assert_eq!(t.i1 as usize & 1, y & 1, "h {h} y {y}");
                }
            }
            for (c, t) in vertical_down_taps(h, ch, Siting::Between, true)
                .iter()
                .enumerate()
            {
                for &(r, w) in t {
                    if w > 0.0 {
                        assert!((r as usize) < h);
                        assert_eq!(r as usize & 1, c & 1, "h {h} c {c}");
                    }
                }
            }
        }
    }
}
