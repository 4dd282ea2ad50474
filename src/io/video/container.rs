//! Video container files by extension: the video codecs fxrun writes by default, and
//! which audio and subtitle codecs each container takes (what is copied, converted or
//! dropped when the audio and subtitles of the input are carried over).

use std::path::Path;

/// How a container takes subtitle streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subtitles {
    /// Any subtitle codec is copied (Matroska).
    Copy,
    /// Text subtitles are converted to this codec (`mov_text`, `webvtt`); bitmap
    /// subtitles (DVD, Blu-ray, DVB) are dropped.
    TextAs(&'static str),
    /// Only these codecs are copied; others are dropped.
    Only(&'static [&'static str]),
}

/// What fxrun knows of a container.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Container {
    /// File extensions, lower case.
    pub extensions: &'static [&'static str],
    /// Video encoders tried in order for output of at most 8 bits, and above 8 bits
    /// (the first one this ffmpeg has is used).
    pub codecs_8bit: &'static [&'static str],
    pub codecs_high: &'static [&'static str],
    /// Audio codecs copied as they are; `None`: any.
    pub audio_copy: Option<&'static [&'static str]>,
    /// The encoder (and its options) other audio is converted with (empty when every
    /// codec is copied).
    pub audio_convert: &'static [&'static str],
    pub subtitles: Subtitles,
}

/// Text subtitle codecs ffmpeg converts between.
pub const TEXT_SUBTITLES: [&str; 6] = ["subrip", "ass", "ssa", "webvtt", "mov_text", "text"];

// Not FLAC: FFmpeg 5.1 (Debian 12's) writes it into MP4 only with `-strict
// experimental` and otherwise fails at the header, after the first frames; it
// becomes AAC.
const MP4_AUDIO: &[&str] = &["aac", "mp3", "ac3", "eac3", "alac", "opus"];
const MOV_AUDIO: &[&str] = &[
    "aac",
    "mp3",
    "ac3",
    "eac3",
    "alac",
    "pcm_s16le",
    "pcm_s16be",
    "pcm_s24le",
    "pcm_s24be",
];
const TS_AUDIO: &[&str] = &["aac", "mp3", "mp2", "ac3", "eac3", "opus"];
const H264_FIRST: &[&str] = &["libx264", "libx265", "mpeg4"];
const H264_HIGH: &[&str] = &["libx264", "libx265"];

/// The containers fxrun reads and writes through ffmpeg.
pub const CONTAINERS: &[Container] = &[
    Container {
        extensions: &["mp4", "m4v"],
        codecs_8bit: H264_FIRST,
        codecs_high: H264_HIGH,
        audio_copy: Some(MP4_AUDIO),
        audio_convert: &["aac", "-b:a", "192k"],
        subtitles: Subtitles::TextAs("mov_text"),
    },
    Container {
        extensions: &["mov"],
        codecs_8bit: H264_FIRST,
        codecs_high: H264_HIGH,
        audio_copy: Some(MOV_AUDIO),
        audio_convert: &["aac", "-b:a", "192k"],
        subtitles: Subtitles::TextAs("mov_text"),
    },
    Container {
        extensions: &["mkv"],
        codecs_8bit: H264_FIRST,
        codecs_high: H264_HIGH,
        audio_copy: None,
        audio_convert: &[],
        subtitles: Subtitles::Copy,
    },
    Container {
        extensions: &["webm"],
        codecs_8bit: &["libvpx-vp9", "libaom-av1", "libsvtav1"],
        codecs_high: &["libvpx-vp9", "libaom-av1", "libsvtav1"],
        audio_copy: Some(&["opus", "vorbis"]),
        audio_convert: &["libopus", "-b:a", "160k"],
        subtitles: Subtitles::TextAs("webvtt"),
    },
    Container {
        extensions: &["avi"],
        codecs_8bit: H264_FIRST,
        codecs_high: H264_HIGH,
        audio_copy: Some(&["mp3", "ac3", "aac", "pcm_s16le", "pcm_u8"]),
        audio_convert: &["ac3", "-b:a", "384k"],
        subtitles: Subtitles::Only(&[]),
    },
    Container {
        extensions: &["mxf"],
        codecs_8bit: &["libx264", "mpeg2video"],
        codecs_high: &["libx264"],
        // MXF takes 48 kHz PCM only: every stream is converted (PCM losslessly).
        audio_copy: Some(&[]),
        audio_convert: &["pcm_s24le", "-ar", "48000"],
        subtitles: Subtitles::Only(&[]),
    },
    Container {
        extensions: &["ts", "m2ts", "mts"],
        codecs_8bit: H264_FIRST,
        codecs_high: H264_HIGH,
        audio_copy: Some(TS_AUDIO),
        audio_convert: &["aac", "-b:a", "192k"],
        subtitles: Subtitles::Only(&["dvb_subtitle"]),
    },
];

impl Container {
    /// The container of a path's extension (case-insensitive).
    pub fn of_path(p: &Path) -> Option<&'static Container> {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        CONTAINERS
            .iter()
            .find(|c| c.extensions.contains(&ext.as_str()))
    }

    /// Whether an audio stream of `codec` is copied (else converted).
    pub fn copies_audio(&self, codec: &str) -> bool {
        self.audio_copy.is_none_or(|list| list.contains(&codec))
    }

    /// The subtitle codec a stream of `codec` is written with: `copy`, a conversion,
    /// or `None` when the container cannot hold it (the stream is dropped).
    pub fn subtitle_codec(&self, codec: &str) -> Option<&'static str> {
        match self.subtitles {
            Subtitles::Copy => Some("copy"),
            Subtitles::TextAs(target) if codec == target => Some("copy"),
            Subtitles::TextAs(target) => TEXT_SUBTITLES.contains(&codec).then_some(target),
            Subtitles::Only(list) => list.contains(&codec).then_some("copy"),
        }
    }
}

/// Whether `p` names a video container file fxrun reads and writes through ffmpeg
/// (by its extension: [`CONTAINERS`]).
pub fn is_video_path(p: &Path) -> bool {
    Container::of_path(p).is_some()
}

/// The extensions of [`CONTAINERS`], for messages.
pub fn extensions() -> Vec<&'static str> {
    CONTAINERS
        .iter()
        .flat_map(|c| c.extensions.iter().copied())
        .collect()
}
