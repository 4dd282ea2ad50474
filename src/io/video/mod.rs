//! Video container files (`.mp4`, `.mov`, `.mkv`, `.webm`, `.avi`, `.mxf`, `.m4v`,
//! `.ts`) through ffmpeg: fxrun runs `ffprobe` and `ffmpeg` as child processes and
//! talks y4m with them. No codec code here.
//!
//! - [`probe`]: the file's video stream (size, frame rate, pixel format, colour range
//!   and matrix, field order, frame count) and its audio and subtitle streams, from
//!   `ffprobe -print_format json`.
//! - [`Decoder`]: `ffmpeg -i IN ... -f yuv4mpegpipe -` (the video stream at its
//!   layout and depth, `yuv420p10le` for 10-bit 4:2:0), read with
//!   [`super::y4m::Y4mReader`]; a non-zero exit is the input's fault.
//! - [`Encoder`]: `ffmpeg -f yuv4mpegpipe -i pipe:0 [-i IN] ... TEMP.EXT`: a
//!   [`super::OutputTarget`] the y4m stream is written into. The default video encoder
//!   is H.264 (libx264) `yuv420p`, `yuv420p10le` above 8 bits (VP9 for `.webm`); the
//!   audio and subtitles of an input video are copied, converted where the container
//!   needs it (`.webm` takes Opus/Vorbis, `.mp4` text subtitles as `mov_text`), or
//!   dropped with a note. The file is written to a temporary next to the output with
//!   the same extension and renamed once ffmpeg succeeded.
//!
//! The children run in their own process group, so a Ctrl-C in the terminal reaches
//! fxrun alone, which stops the run and ends them. Files: `container` (extensions and
//! what each container takes), `audio` (what happens to each audio stream: copied
//! or transcoded, decided before ffmpeg starts), `pix_fmt` (ffmpeg pixel format names), `probe`,
//! `decode`, `encode`, `process` (finding, starting and reaping the programs).

mod audio;
pub mod color;
mod container;
mod decode;
mod encode;
pub mod pix_fmt;
mod probe;
mod process;

pub use audio::{plan_audio, AudioAction, AudioStream};
pub use color::{video_color, HdrMetadata, Mastering, VideoColor};
pub use container::{is_video_path, Container, Subtitles, CONTAINERS};
pub use decode::{decode_args, Decoder};
pub use encode::{EncodeOptions, Encoder, MediaSource};
pub use probe::{parse as parse_probe, probe, probe_args, OtherStream, VideoInfo};
pub use process::{find_program, shell_line};

use super::IoError;
use std::path::PathBuf;

/// How to get ffmpeg, for the error when it is missing.
pub const INSTALL_HINT: &str = "install it (Debian/Ubuntu: apt-get install ffmpeg; Fedora: dnf install ffmpeg; macOS: brew install ffmpeg; Windows: winget install ffmpeg) and make sure it is on PATH";

/// Errors of reading and writing video files through ffmpeg. Every message starts with
/// the video file's path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VideoError {
    /// `ffmpeg` or `ffprobe` is not on `PATH` (input rejected: exit 1 in fxrun).
    #[error("{}: {program} was not found on PATH (fxrun reads and writes video files with ffmpeg and ffprobe): {INSTALL_HINT}", path.display())]
    Missing {
        path: PathBuf,
        program: &'static str,
    },
    /// The program could not be started or talked to.
    #[error("{}: {program}: {source}", path.display())]
    Io {
        path: PathBuf,
        program: &'static str,
        source: std::io::Error,
    },
    /// The input video was rejected: ffprobe or ffmpeg cannot read it (with its last
    /// stderr lines), or it has no video stream.
    #[error("{}: {message}", path.display())]
    Input { path: PathBuf, message: String },
    /// An output option was rejected (an encoder ffmpeg does not have, a pixel format
    /// it does not take, an extension that is no container).
    #[error("{}: {message}", path.display())]
    Option { path: PathBuf, message: String },
}

impl From<VideoError> for IoError {
    /// `Missing`, `Input` and `Option` are input errors ([`IoError::Decode`],
    /// [`IoError::Unsupported`]); `Io` is [`IoError::Io`].
    fn from(e: VideoError) -> IoError {
        match e {
            VideoError::Missing { path, program } => IoError::Unsupported {
                path,
                message: format!(
                    "{program} was not found on PATH (fxrun reads and writes video files with ffmpeg and ffprobe): {INSTALL_HINT}"
                ),
            },
            VideoError::Io {
                path,
                program,
                source,
            } => IoError::Io {
                path,
                source: std::io::Error::new(source.kind(), format!("{program}: {source}")),
            },
            VideoError::Input { path, message } => IoError::Decode { path, message },
            VideoError::Option { path, message } => IoError::Unsupported { path, message },
        }
    }
}
