//! Streams of frames in one pipe or file, for sequence jobs (and rendered scene
//! sequences): y4m on stdin and stdout, `.y4m` files (written atomically), and video
//! files (`.mp4`, `.mkv`, ...) through ffmpeg child processes ([`crate::io::video`]).
//!
//! [`OpenedInput::open`] reads the stream's header (for a video: probes it and starts
//! the decoder) so that the caller knows the size, rate, depth and colour before the
//! run; [`OpenedInput::into_source`] makes the [`FrameSource`]. [`open_output`] makes
//! the [`FrameSink`] and says which texture format the effect should render for it
//! ([`texture_format_for_depth`]). A file output is made final only when the run
//! completes ([`FrameSink::finish`]); a failed or interrupted run leaves no partial
//! file and keeps an existing one ([`FrameSink::abort`]).

use super::error::RunError;
use super::frames::{FrameSink, FrameSource, SideLimit, SourceFrame};
use super::sources::{Y4mSink, Y4mSource};
use crate::io::video::{
    video_color, Decoder, EncodeOptions, Encoder, HdrMetadata, MediaSource, VideoInfo,
};
use crate::io::y4m::{Y4mHeader, Y4mReader, YuvConversion};
use crate::io::{AtomicFile, IoError};
use crate::script::types::Format;
use std::path::PathBuf;
use std::process::ChildStdout;

/// Where a stream of frames is read from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StreamInput {
    /// YUV4MPEG2 on stdin.
    Stdin,
    /// A `.y4m` file.
    Y4mFile(PathBuf),
    /// A video file, decoded by ffmpeg.
    Video(PathBuf),
}

/// Where a stream of frames is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StreamOutput {
    /// YUV4MPEG2 on stdout.
    Stdout,
    /// A `.y4m` file (written to a temporary, renamed at the end).
    Y4mFile(PathBuf),
    /// A video file, encoded by ffmpeg (to a temporary, renamed at the end).
    Video(PathBuf),
}

impl StreamOutput {
    /// The name of the output in messages (`stdout`, the path).
    pub fn name(&self) -> String {
        match self {
            StreamOutput::Stdout => "stdout".into(),
            StreamOutput::Y4mFile(p) | StreamOutput::Video(p) => p.display().to_string(),
        }
    }
}

/// The texture format an effect renders for a y4m stream of `depth` bits: 8-bit sRGB
/// for 8 bits, rgba16f up to 10 bits, rgba32f above (a half float holds 11
/// significant bits).
pub fn texture_format_for_depth(depth: u8) -> Format {
    match depth {
        0..=8 => Format::Rgba8Srgb,
        9..=10 => Format::Rgba16f,
        _ => Format::Rgba32f,
    }
}

enum Reader {
    Stdin(Y4mReader<std::io::BufReader<std::io::Stdin>>),
    File(Y4mReader<std::fs::File>),
    Video(Y4mReader<ChildStdout>, Box<Decoder>),
}

/// An input stream whose header has been read.
pub struct OpenedInput {
    /// The y4m header (of ffmpeg's output, for a video).
    pub header: Y4mHeader,
    /// How its Y'CbCr maps to RGB: the header's range (`XCOLORRANGE`), else the
    /// video's; the video's matrix, else BT.601 up to 576 lines and BT.709 above.
    pub conversion: YuvConversion,
    /// The video file's streams (a video input).
    pub video: Option<VideoInfo>,
    /// Frames in the stream, when known (a y4m file's length; a video's frame count
    /// where the container records it).
    pub frames: Option<u64>,
    /// The child processes run (ffprobe, ffmpeg), as command lines.
    pub commands: Vec<String>,
    /// Doubts about the input's colour (tags that contradict each other, an HDR
    /// stream of 8 bits), for the user.
    pub color_warnings: Vec<String>,
    reader: Reader,
}

impl OpenedInput {
    /// Open the stream and read its header.
    pub fn open(input: &StreamInput) -> Result<OpenedInput, RunError> {
        let bad = |e: crate::io::y4m::Y4mError| RunError::from(IoError::from(e));
        match input {
            StreamInput::Stdin => {
                let stdin = std::io::BufReader::with_capacity(1 << 20, std::io::stdin());
                let reader = Y4mReader::new(stdin, "stdin").map_err(bad)?;
                Ok(OpenedInput::new(Reader::Stdin(reader), None, Vec::new()))
            }
            StreamInput::Y4mFile(path) => {
                let file = std::fs::File::open(path).map_err(|source| {
                    RunError::from(IoError::Io {
                        path: path.clone(),
                        source,
                    })
                })?;
                let len = file.metadata().map(|m| m.len()).ok();
                let reader = Y4mReader::new(file, path.display().to_string()).map_err(bad)?;
                let mut opened = OpenedInput::new(Reader::File(reader), None, Vec::new());
                if let (Some(len), Reader::File(r)) = (len, &opened.reader) {
                    opened.frames = r.frames_in(len);
                }
                Ok(opened)
            }
            StreamInput::Video(path) => {
                let (info, probe_line) =
                    crate::io::video::probe(path).map_err(|e| RunError::from(IoError::from(e)))?;
                let color = video_color(&info).map_err(|message| {
                    RunError::from(IoError::Unsupported {
                        path: path.clone(),
                        message,
                    })
                })?;
                let mut decoder =
                    Decoder::spawn(&info).map_err(|e| RunError::from(IoError::from(e)))?;
                let commands = vec![probe_line, decoder.command_line().to_string()];
                let Some(stdout) = decoder.take_stdout() else {
                    return Err(RunError::Other("ffmpeg's output is not a pipe".into()));
                };
                let reader = match Y4mReader::new(stdout, path.display().to_string()) {
                    Ok(r) => r,
                    // No header: ffmpeg failed on the file (its error says why).
                    Err(e) => {
                        return Err(match decoder.finish() {
                            Err(v) => RunError::from(IoError::from(v)),
                            Ok(()) => bad(e),
                        })
                    }
                };
                let frames = info.frames;
                let mut opened = OpenedInput::new(
                    Reader::Video(reader, Box::new(decoder)),
                    Some(info),
                    commands,
                );
                opened.frames = frames;
                opened.conversion.color = color.color;
                opened.color_warnings = color.warnings;
                Ok(opened)
            }
        }
    }

    fn new(reader: Reader, video: Option<VideoInfo>, commands: Vec<String>) -> OpenedInput {
        let header = match &reader {
            Reader::Stdin(r) => r.header().clone(),
            Reader::File(r) => r.header().clone(),
            Reader::Video(r, _) => r.header().clone(),
        };
        let mut conversion = YuvConversion::for_header(&header);
        if let Some(v) = &video {
            if let Some(m) = v.matrix {
                conversion.matrix = m;
            }
            if let (None, Some(r)) = (header.range_hint(), v.range) {
                conversion.range = r;
            }
        }
        OpenedInput {
            header,
            conversion,
            video,
            frames: None,
            commands,
            color_warnings: Vec::new(),
            reader,
        }
    }

    /// Whether the frames are HDR (PQ or HLG).
    pub fn is_hdr(&self) -> bool {
        self.conversion.color.transfer.is_hdr()
    }

    /// The HDR metadata of a video input (empty for y4m streams).
    pub fn hdr_metadata(&self) -> HdrMetadata {
        self.video.as_ref().map(|v| v.hdr).unwrap_or_default()
    }

    /// Whether the stream's colour is ambiguous: a y4m stream above 8 bits (often
    /// HDR) whose colour nobody said.
    pub fn color_is_ambiguous(&self) -> bool {
        self.video.is_none() && self.header.depth > 8
    }

    /// The source of the stream's frames `skip` to `last` (0-based, inclusive;
    /// `None`: to the end).
    pub fn into_source(self, skip: u64, last: Option<u64>) -> Box<dyn FrameSource> {
        fn source<R: std::io::Read + Send>(
            r: Y4mReader<R>,
            c: YuvConversion,
            frames: Option<u64>,
            skip: u64,
            last: Option<u64>,
        ) -> Y4mSource<R> {
            let mut s = Y4mSource::new(r, c);
            (s.skip, s.last, s.frames) = (skip, last, frames);
            s
        }
        let (c, n) = (self.conversion, self.frames);
        match self.reader {
            Reader::Stdin(r) => Box::new(source(r, c, n, skip, last)),
            Reader::File(r) => Box::new(source(r, c, n, skip, last)),
            Reader::Video(r, decoder) => Box::new(VideoSource {
                inner: source(r, c, n, skip, last),
                decoder,
                ended: false,
            }),
        }
    }
}

/// Frames of a video file: ffmpeg's y4m output, and ffmpeg's exit status at its end
/// (a failed decode is the file's error, with ffmpeg's last stderr lines). Dropping
/// it ends ffmpeg.
struct VideoSource {
    inner: Y4mSource<ChildStdout>,
    decoder: Box<Decoder>,
    ended: bool,
}

impl VideoSource {
    fn failed(&self, e: crate::io::video::VideoError) -> SourceFrame {
        let number = self.inner.reader.frames_read();
        SourceFrame {
            number,
            name: format!("{} frame {number}", self.inner.reader.name()),
            image: Err(e.into()),
            aux: Vec::new(),
        }
    }
}

impl FrameSource for VideoSource {
    fn frame_count(&self) -> Option<u64> {
        self.inner.frame_count()
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        if self.ended {
            return None;
        }
        match self.inner.next_frame() {
            Some(f) if f.image.is_ok() => Some(f),
            Some(f) => {
                self.ended = true;
                match self.decoder.failure_after_broken_stream() {
                    Some(e) => Some(self.failed(e)),
                    None => Some(f),
                }
            }
            None => {
                self.ended = true;
                if self.inner.past_last() {
                    // `--frames` ended before the video: ffmpeg is not needed any more.
                    self.decoder.stop();
                    return None;
                }
                match self.decoder.finish() {
                    Ok(()) => None,
                    Err(e) => Some(self.failed(e)),
                }
            }
        }
    }
    fn set_limit(&mut self, limit: SideLimit) {
        self.inner.set_limit(limit);
    }
    fn set_plane_route(&mut self, route: super::planes::PlaneRoute) {
        self.inner.set_plane_route(route);
    }
}

/// What an output stream is written with.
#[derive(Debug, Clone)]
pub struct OutputSettings {
    /// Header fields passed on: frame rate, interlacing, aspect, chroma layout, depth,
    /// `X` fields (the size is the first frame's).
    pub template: Y4mHeader,
    pub conversion: YuvConversion,
    /// Video files: the encoder, its settings, the audio and subtitles to copy.
    pub codec: Option<String>,
    pub crf: Option<u32>,
    pub preset: Option<String>,
    pub pix_fmt: Option<String>,
    pub media: Option<MediaSource>,
    /// Colour tags of an input video carried over (primaries, transfer).
    pub primaries: Option<String>,
    pub transfer: Option<String>,
    /// HDR metadata written into an HDR video output.
    pub hdr: Option<HdrMetadata>,
}

impl OutputSettings {
    /// Settings with `template` and `conversion` and no video options.
    pub fn new(template: Y4mHeader, conversion: YuvConversion) -> OutputSettings {
        OutputSettings {
            template,
            conversion,
            codec: None,
            crf: None,
            preset: None,
            pix_fmt: None,
            media: None,
            primaries: None,
            transfer: None,
            hdr: None,
        }
    }

    /// Tags and depth of an output whose signal is `conversion.color` but not the
    /// input's: the tags named after the signal.
    pub fn tag_signal(&mut self) {
        let c = self.conversion.color;
        self.primaries = Some(c.primaries.ffmpeg_name().to_string());
        self.transfer = Some(c.transfer.ffmpeg_name().to_string());
    }
}

/// An output stream ready for a run.
pub struct OpenedOutput {
    pub sink: Box<dyn FrameSink>,
    /// The texture format the effect should render ([`texture_format_for_depth`]).
    pub texture_format: Format,
    /// The child process run (ffmpeg), as a command line.
    pub commands: Vec<String>,
    /// What happens to the input video's other streams (converted, dropped).
    pub notes: Vec<String>,
}

/// Open an output stream: a file's temporary is created (an encoder started) now.
/// Errors: a depth the layout cannot be written with, ffmpeg missing, an encoder it
/// does not have (input errors); a file that cannot be created (I/O).
pub fn open_output(output: &StreamOutput, s: &OutputSettings) -> Result<OpenedOutput, RunError> {
    let t = &s.template;
    if !Y4mHeader::depth_supported(t.colorspace, t.depth) {
        return Err(RunError::from(IoError::Unsupported {
            path: output.name().into(),
            message: format!("C{} has no {}-bit y4m form", t.colorspace.tag(), t.depth),
        }));
    }
    let name = output.name();
    fn sink_of<W: crate::io::OutputTarget + 'static>(
        w: W,
        s: &OutputSettings,
        name: &str,
    ) -> Box<dyn FrameSink> {
        Box::new(Y4mSink::new(w, s.template.clone(), s.conversion, name))
    }
    // A signal other than sRGB is encoded from linear floats (never from 8-bit sRGB).
    let texture_format = match texture_format_for_depth(t.depth) {
        Format::Rgba8Srgb if !s.conversion.color.is_srgb() => Format::Rgba16f,
        f => f,
    };
    let (sink, commands, notes) = match output {
        StreamOutput::Stdout => {
            let out = std::io::BufWriter::with_capacity(1 << 20, std::io::stdout());
            (sink_of(out, s, &name), Vec::new(), Vec::new())
        }
        StreamOutput::Y4mFile(path) => {
            let file = AtomicFile::create(path)?;
            (sink_of(file, s, &name), Vec::new(), Vec::new())
        }
        StreamOutput::Video(path) => {
            let opts = EncodeOptions {
                codec: s.codec.clone(),
                crf: s.crf,
                preset: s.preset.clone(),
                pix_fmt: s.pix_fmt.clone(),
                depth: t.depth,
                range: s.conversion.range,
                matrix: s.conversion.matrix,
                primaries: s.primaries.clone(),
                transfer: s.transfer.clone(),
                media: s.media.clone(),
                hdr: s.hdr,
            };
            let encoder =
                Encoder::spawn(path, &opts).map_err(|e| RunError::from(IoError::from(e)))?;
            let commands = vec![encoder.command_line().to_string()];
            let notes = encoder.notes().to_vec();
            (sink_of(encoder, s, &name), commands, notes)
        }
    };
    Ok(OpenedOutput {
        sink,
        texture_format,
        commands,
        notes,
    })
}
