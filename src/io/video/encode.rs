//! Encoding a y4m stream into a video file: ffmpeg as a child process reading y4m on
//! its stdin and writing a temporary next to the output (`.NAME.fxtmp-<pid>-<n>.EXT`),
//! renamed over the output once it succeeded; the audio and subtitles of the input
//! video copied (or converted where the container needs it) from that file.

use super::audio::{per_stream, plan_audio, AudioStream};
use super::color::HdrMetadata;
use super::container::Container;
use super::pix_fmt::{self, Layout};
use super::probe::VideoInfo;
use super::process::{file_arg, require, shell_line, status_text, Child};
use super::VideoError;
use crate::io::yuv::{Matrix, Range};
use crate::io::{create_temporary, rename_into_place, IoError, OutputTarget};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{ChildStdin, Command, Stdio};

/// Encoders that take `-crf`, and the value used when none is given.
const CRF_DEFAULTS: &[(&str, u32)] = &[
    ("libx264", 18),
    ("libx264rgb", 18),
    ("libx265", 20),
    ("libvpx", 10),
    ("libvpx-vp9", 24),
    ("libaom-av1", 24),
    ("libsvtav1", 30),
];

/// The `-preset` values of libx264 and libx265 (checked before ffmpeg starts: ffmpeg
/// would only fail once the first frame arrives).
const X26X_PRESETS: [&str; 10] = [
    "ultrafast",
    "superfast",
    "veryfast",
    "faster",
    "fast",
    "medium",
    "slow",
    "slower",
    "veryslow",
    "placebo",
];

/// Where the audio and subtitles of the output come from: the input video, and the
/// part of it the output covers (`--frames`).
#[derive(Debug, Clone)]
pub struct MediaSource {
    pub info: VideoInfo,
    /// Seconds from the start of the input.
    pub start: f64,
    /// Seconds taken (`None`: to the end).
    pub duration: Option<f64>,
}

/// How to encode.
#[derive(Debug, Clone)]
pub struct EncodeOptions {
    /// The video encoder (`--codec`); `None`: the container's default for the depth.
    pub codec: Option<String>,
    /// Constant-quality factor (`--crf`); `None`: the encoder's default here.
    pub crf: Option<u32>,
    /// Encoder speed preset (`--preset`), passed as `-preset`.
    pub preset: Option<String>,
    /// The pixel format (`--pix-fmt`); `None`: 4:2:0 at the frames' depth, as far as
    /// the encoder takes it.
    pub pix_fmt: Option<String>,
    /// Bits per sample of the frames written to the encoder.
    pub depth: u8,
    /// How the frames' Y'CbCr was made (written into the file's colour tags).
    pub range: Range,
    pub matrix: Matrix,
    /// Colour primaries and transfer tags to carry over (from an input video).
    pub primaries: Option<String>,
    pub transfer: Option<String>,
    /// Audio and subtitles to copy.
    pub media: Option<MediaSource>,
    /// HDR metadata (mastering display, content light level) to write, for PQ and
    /// HLG outputs: as SEI by libx265 and libx264.
    pub hdr: Option<HdrMetadata>,
}

impl EncodeOptions {
    /// Whether the output is HDR (tagged PQ or HLG).
    fn is_hdr(&self) -> bool {
        matches!(self.transfer.as_deref(), Some("smpte2084" | "arib-std-b67"))
    }
}

/// The encoders tried for an output with no `--codec`: the container's list, with
/// libx265 first for HDR outputs (HEVC Main 10 is what HDR10 and HLG players expect,
/// and ffprobe reads its mastering-display SEI back).
fn default_codecs(container: &Container, opts: &EncodeOptions) -> Vec<&'static str> {
    let list = if opts.depth > 8 {
        container.codecs_high
    } else {
        container.codecs_8bit
    };
    let mut v: Vec<&'static str> = list.to_vec();
    if opts.is_hdr() && v.contains(&"libx265") {
        v.retain(|c| *c != "libx265");
        v.insert(0, "libx265");
    }
    v
}

/// The `-x265-params` / `-x264-params` value: x265's log level, and the HDR
/// metadata for HDR outputs.
fn x26x_params(codec: &str, opts: &EncodeOptions) -> Option<String> {
    let mut p: Vec<String> = Vec::new();
    if codec == "libx265" {
        // x265 logs its statistics itself, whatever ffmpeg's log level.
        p.push("log-level=error".into());
    }
    if opts.is_hdr() {
        if codec == "libx265" && opts.transfer.as_deref() == Some("smpte2084") {
            p.push("hdr10=1".into());
        }
        if let Some(h) = &opts.hdr {
            p.extend(h.encoder_params(codec));
        }
    }
    (!p.is_empty()).then(|| p.join(":"))
}

/// An ffmpeg child encoding the y4m written to it ([`Write`]) into a video file.
/// [`OutputTarget::commit`] waits for it and renames the temporary over the output;
/// [`OutputTarget::abandon`] (or dropping it uncommitted) kills it and removes the
/// temporary, so an existing output is untouched.
pub struct Encoder {
    child: Child,
    stdin: Option<BufWriter<ChildStdin>>,
    path: PathBuf,
    tmp: Option<PathBuf>,
    line: String,
    notes: Vec<String>,
}

/// The pixel formats `ffmpeg -h encoder=NAME` lists; `None` when ffmpeg does not know
/// the encoder.
fn encoder_formats(ffmpeg: &Path, name: &str) -> std::io::Result<Option<Vec<String>>> {
    let out = Command::new(ffmpeg)
        .args(["-hide_banner", "-h", &format!("encoder={name}")])
        .stdin(Stdio::null())
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !text.contains(&format!("Encoder {name} ")) {
        return Ok(None);
    }
    Ok(Some(
        text.lines()
            .find_map(|l| l.trim().strip_prefix("Supported pixel formats:"))
            .map(|l| l.split_whitespace().map(String::from).collect())
            .unwrap_or_default(),
    ))
}

impl Encoder {
    /// Start ffmpeg writing `output` (its container chosen by the extension).
    /// Errors: not a known container or an encoder ffmpeg does not have
    /// ([`VideoError::Option`]), ffmpeg missing ([`VideoError::Missing`]), the temporary
    /// or the process cannot be made ([`VideoError::Io`]).
    pub fn spawn(output: &Path, opts: &EncodeOptions) -> Result<Encoder, VideoError> {
        let container = Container::of_path(output).ok_or_else(|| {
            option_error(
                output,
                format!(
                    "not a video file extension (known: {})",
                    super::container::extensions().join(", ")
                ),
            )
        })?;
        let ffmpeg = require("ffmpeg", output)?;
        let (codec, formats) = choose_encoder(&ffmpeg, output, container, opts)?;
        let choice = check_encoder_options(output, container, codec, &formats, opts)?;
        // the audio's fate, before ffmpeg starts (it writes the header, where a
        // codec the container cannot hold fails, only once the first frames came in)
        let audio = match &opts.media {
            Some(m) => plan_audio(container, &m.info.audio, |e| {
                matches!(encoder_formats(&ffmpeg, e), Ok(Some(_)))
            })
            .map_err(|e| option_error(output, format!("{}: {e}", m.info.path.display())))?,
            None => Vec::new(),
        };
        let ext = output
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (tmp, file) = create_temporary(output, Some(&ext)).map_err(|e| match e {
            IoError::Io { source, .. } => io_error(output, source),
            other => io_error(output, std::io::Error::other(other.to_string())),
        })?;
        drop(file);
        let mut notes = Vec::new();
        if let (true, Some(h)) = (opts.is_hdr(), &opts.hdr) {
            if h.encoder_params(&choice.codec).is_empty() {
                notes.push(format!(
                    "{}: the input's mastering-display / content-light metadata is not written by {} (libx265 and libx264 write it)",
                    output.display(),
                    choice.codec
                ));
            }
        }
        let args = encode_args(&tmp, &choice, opts, &audio, &mut notes);
        let line = shell_line("ffmpeg", &args);
        let child = Child::spawn("ffmpeg", &ffmpeg, &args, Stdio::piped(), Stdio::null());
        let mut child = match child {
            Ok(c) => c,
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                return Err(io_error(output, e));
            }
        };
        let stdin = child
            .child
            .stdin
            .take()
            .map(|s| BufWriter::with_capacity(1 << 20, s));
        Ok(Encoder {
            child,
            stdin,
            path: output.to_path_buf(),
            tmp: Some(tmp),
            line,
            notes,
        })
    }

    /// The command line run (for `-v`; the temporary's name in place of the output).
    pub fn command_line(&self) -> &str {
        &self.line
    }

    /// What happens to the input's other streams: audio converted, subtitles converted
    /// or dropped (the container cannot hold them).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The output file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A write failed: ffmpeg has most likely stopped; say why with its stderr.
    fn stopped(&mut self, e: std::io::Error) -> std::io::Error {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            return e;
        }
        let status = self.child.wait().map(status_text).unwrap_or_default();
        std::io::Error::other(format!("ffmpeg stopped ({status}):\n{}", self.child.tail()))
    }
}

impl Write for Encoder {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = match self.stdin.as_mut() {
            Some(s) => s.write(buf),
            None => return Err(std::io::Error::other("the encoder is finished")),
        };
        r.map_err(|e| self.stopped(e))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        let r = match self.stdin.as_mut() {
            Some(s) => s.flush(),
            None => Ok(()),
        };
        r.map_err(|e| self.stopped(e))
    }
}

impl OutputTarget for Encoder {
    fn commit(&mut self) -> Result<(), IoError> {
        let path = self.path.clone();
        let fail = |message: String| IoError::Io {
            path: path.clone(),
            source: std::io::Error::other(message),
        };
        if let Some(mut s) = self.stdin.take() {
            if let Err(e) = s.flush() {
                drop(s);
                let e = self.stopped(e);
                self.abandon();
                return Err(fail(e.to_string()));
            }
            // Dropping stdin ends the stream: ffmpeg finishes the file.
        }
        let status = self.child.wait();
        let ok = matches!(&status, Ok(s) if s.success());
        if !ok {
            let message = match status {
                Ok(s) => format!(
                    "ffmpeg could not write the video ({}):\n{}",
                    status_text(s),
                    self.child.tail()
                ),
                Err(e) => format!("waiting for ffmpeg: {e}"),
            };
            self.abandon();
            return Err(fail(message));
        }
        self.child.log_stderr("encoding");
        if let Some(tmp) = self.tmp.take() {
            if let Err(e) = rename_into_place(&tmp, &path) {
                let _ = std::fs::remove_file(&tmp);
                return Err(e);
            }
        }
        Ok(())
    }

    fn abandon(&mut self) {
        // ffmpeg first: a full pipe would block the flush of stdin.
        self.child.kill();
        self.stdin = None;
        if let Some(tmp) = self.tmp.take() {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

impl Drop for Encoder {
    fn drop(&mut self) {
        if self.tmp.is_some() {
            self.abandon();
        }
    }
}

/// An option ffmpeg cannot encode `output` with.
fn option_error(output: &Path, message: String) -> VideoError {
    VideoError::Option {
        path: output.to_path_buf(),
        message,
    }
}

/// A failure running ffmpeg for `output`.
fn io_error(output: &Path, source: std::io::Error) -> VideoError {
    VideoError::Io {
        path: output.to_path_buf(),
        program: "ffmpeg",
        source,
    }
}

/// The encoder for `output` and the pixel formats it takes: `--codec`, else the first
/// of the container's usual encoders this ffmpeg has.
fn choose_encoder(
    ffmpeg: &Path,
    output: &Path,
    container: &Container,
    opts: &EncodeOptions,
) -> Result<(String, Vec<String>), VideoError> {
    match &opts.codec {
        Some(c) => {
            let unknown = || {
                format!(
                    "--codec {c}: this ffmpeg has no such encoder (`ffmpeg -encoders` lists them)"
                )
            };
            let f = encoder_formats(ffmpeg, c)
                .map_err(|e| io_error(output, e))?
                .ok_or_else(|| option_error(output, unknown()))?;
            Ok((c.clone(), f))
        }
        None => {
            let list = default_codecs(container, opts);
            for c in &list {
                if let Some(f) = encoder_formats(ffmpeg, c).map_err(|e| io_error(output, e))? {
                    return Ok((c.to_string(), f));
                }
            }
            Err(option_error(
                output,
                format!(
                    "this ffmpeg has none of the encoders used for this container ({}): choose one with --codec (`ffmpeg -encoders` lists them)",
                    list.join(", ")
                ),
            ))
        }
    }
}

/// The encoder chosen for an output, and how it is set.
struct EncoderChoice<'a> {
    container: &'a Container,
    codec: String,
    /// `--pix-fmt`, else the best of the encoder's formats for the depth.
    pix_fmt: Option<String>,
    /// The encoder's constant-quality factor when `--crf` is not given.
    crf_default: Option<u32>,
}

/// `--pix-fmt`, `--crf` and `--preset` checked against the encoder `codec` (taking
/// `formats`).
fn check_encoder_options<'a>(
    output: &Path,
    container: &'a Container,
    codec: String,
    formats: &[String],
    opts: &EncodeOptions,
) -> Result<EncoderChoice<'a>, VideoError> {
    let option = |message: String| option_error(output, message);
    let pix_fmt = match &opts.pix_fmt {
        Some(p) if !formats.is_empty() && !formats.contains(p) => {
            return Err(option(format!(
                "--pix-fmt {p}: the encoder {codec} takes {}",
                formats.join(", ")
            )))
        }
        Some(p) => Some(p.clone()),
        None => pix_fmt::choose(formats, Layout::Yuv420, opts.depth),
    };
    let crf_default = CRF_DEFAULTS.iter().find(|(c, _)| *c == codec).map(|c| c.1);
    if opts.crf.is_some() && crf_default.is_none() {
        return Err(option(format!(
            "--crf: the encoder {codec} has no constant-quality factor here (--crf is for {})",
            CRF_DEFAULTS
                .iter()
                .map(|c| c.0)
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    if let Some(p) = &opts.preset {
        if (codec == "libx264" || codec == "libx265") && !X26X_PRESETS.contains(&p.as_str()) {
            return Err(option(format!(
                "--preset {p}: {codec} takes {}",
                X26X_PRESETS.join(", ")
            )));
        }
    }
    Ok(EncoderChoice {
        container,
        codec,
        pix_fmt,
        crf_default,
    })
}

/// The ffmpeg arguments of an encoder writing `tmp` (`audio`: what happens to the
/// input's audio streams); notes about the input's other streams are added to
/// `notes`.
fn encode_args(
    tmp: &Path,
    choice: &EncoderChoice,
    opts: &EncodeOptions,
    audio: &[AudioStream],
    notes: &mut Vec<String>,
) -> Vec<String> {
    let mut a: Vec<String> = Vec::new();
    let mut push = |v: &[&str]| a.extend(v.iter().map(|s| s.to_string()));
    push(&["-hide_banner", "-nostdin", "-loglevel", "error"]);
    push(&["-f", "yuv4mpegpipe", "-i", "pipe:0"]);
    if let Some(m) = &opts.media {
        if m.start > 0.0 {
            push(&["-ss", &format!("{:.6}", m.start)]);
        }
        if let Some(d) = m.duration {
            push(&["-t", &format!("{d:.6}")]);
        }
        push(&["-i", &file_arg(&m.info.path)]);
    }
    push(&["-map", "0:v:0"]);
    if let Some(m) = &opts.media {
        a.extend(media_stream_args(tmp, choice.container, m, audio, notes));
    }
    a.extend(video_codec_args(choice, opts));
    a.extend(color_args(choice.container, opts));
    a.push("-y".into());
    a.push(file_arg(tmp));
    a
}

/// The arguments that carry the input video's audio and subtitles (as the container
/// can hold them) and its metadata into the output; notes about what is converted or
/// dropped are added to `notes`.
fn media_stream_args(
    tmp: &Path,
    container: &Container,
    m: &MediaSource,
    audio: &[AudioStream],
    notes: &mut Vec<String>,
) -> Vec<String> {
    let mut a: Vec<String> = Vec::new();
    let mut push = |v: &[&str]| a.extend(v.iter().map(|s| s.to_string()));
    let name = m.info.path.display();
    let ext = tmp
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (audio_args, audio_notes) = super::audio::audio_args(audio, &name.to_string(), &ext);
    push(&audio_args.iter().map(String::as_str).collect::<Vec<_>>());
    notes.extend(audio_notes);
    let mut j = 0;
    for s in &m.info.subtitles {
        match container.subtitle_codec(&s.codec) {
            Some(c) => {
                push(&["-map", &format!("1:{}", s.index)]);
                push(&[&per_stream("-c:s", 's', j), c]);
                if c != "copy" {
                    notes.push(format!(
                        "{name}: subtitle stream {} ({}) is converted to {c} for .{ext}",
                        s.index, s.codec
                    ));
                }
                j += 1;
            }
            None => notes.push(format!(
                "{name}: subtitle stream {} ({}) cannot be stored in .{ext}: dropped (.mkv keeps every subtitle)",
                s.index, s.codec
            )),
        }
    }
    push(&["-map_metadata", "1"]);
    a
}

/// The video encoder and its settings: pixel format, quality, speed, x26x parameters
/// and preset.
fn video_codec_args(choice: &EncoderChoice, opts: &EncodeOptions) -> Vec<String> {
    let codec = choice.codec.as_str();
    let mut a: Vec<String> = Vec::new();
    let mut push = |v: &[&str]| a.extend(v.iter().map(|s| s.to_string()));
    push(&["-c:v", codec]);
    if let Some(p) = &choice.pix_fmt {
        push(&["-pix_fmt", p]);
    }
    if let Some(crf) = opts.crf.or(choice.crf_default) {
        push(&["-crf", &crf.to_string()]);
        if codec.starts_with("libvpx") || codec == "libaom-av1" {
            push(&["-b:v", "0"]);
        }
    }
    if codec == "libvpx-vp9" {
        push(&["-row-mt", "1", "-cpu-used", "4"]);
    }
    if let Some(p) = x26x_params(codec, opts) {
        let opt = if codec == "libx265" {
            "-x265-params"
        } else {
            "-x264-params"
        };
        push(&[opt, &p]);
    }
    if let Some(p) = &opts.preset {
        push(&["-preset", p]);
    }
    a
}

/// The colour tags of the output (range, matrix, primaries, transfer), and the
/// fast-start layout of MP4 and MOV files.
fn color_args(container: &Container, opts: &EncodeOptions) -> Vec<String> {
    let mut a: Vec<String> = Vec::new();
    let mut push = |v: &[&str]| a.extend(v.iter().map(|s| s.to_string()));
    let range = match opts.range {
        Range::Limited => "tv",
        Range::Full => "pc",
    };
    let matrix = match opts.matrix {
        Matrix::Bt601 => "smpte170m",
        Matrix::Bt709 => "bt709",
        Matrix::Bt2020 => "bt2020nc",
    };
    push(&["-color_range", range, "-colorspace", matrix]);
    if let Some(p) = &opts.primaries {
        push(&["-color_primaries", p]);
    }
    if let Some(t) = &opts.transfer {
        push(&["-color_trc", t]);
    }
    if container.extensions.contains(&"mp4") || container.extensions.contains(&"mov") {
        push(&["-movflags", "+faststart"]);
    }
    a
}
