//! What a video file holds, from `ffprobe -print_format json -show_streams
//! -show_format`: the video stream's size, frame rate, pixel format, colour range and
//! matrix, and the audio and subtitle streams that are carried over to an output.

use super::color::{hdr_metadata, HdrMetadata, SideData};
use super::pix_fmt::{self, Layout};
use super::process::{file_arg, require, shell_line, Child};
use super::VideoError;
use crate::io::yuv::{Matrix, Range};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Stdio;

/// A stream other than the video: its index in the file and its codec.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OtherStream {
    pub index: usize,
    pub codec: String,
}

/// The video stream of a file (the first one that is not a cover picture), and the
/// file's audio and subtitle streams.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoInfo {
    pub path: PathBuf,
    /// Index of the video stream in the file.
    pub index: usize,
    pub codec: String,
    pub width: u32,
    pub height: u32,
    /// Frames per second as numerator / denominator (`r_frame_rate`, else
    /// `avg_frame_rate`); `(0, 0)` when unknown.
    pub fps: (u32, u32),
    /// ffmpeg's pixel format name (`yuv420p10le`).
    pub pix_fmt: String,
    /// The chroma layout and bits per sample of the pixel format.
    pub layout: Layout,
    pub depth: u8,
    /// `color_range` (`tv`: limited, `pc`: full; `yuvj` formats are full).
    pub range: Option<Range>,
    /// `color_space` as a matrix (bt709; smpte170m, bt470bg: BT.601; bt2020nc).
    pub matrix: Option<Matrix>,
    /// The colour tags as ffprobe names them, when known (`bt709`, `smpte170m`,
    /// `bt2020nc`...), carried over to an output.
    pub color_space: Option<String>,
    pub color_primaries: Option<String>,
    pub color_transfer: Option<String>,
    /// `field_order`: `progressive`, `tt`, `bb`, `tb`, `bt`.
    pub field_order: Option<String>,
    /// `nb_frames`, where the container records it (MP4, MOV; not Matroska).
    pub frames: Option<u64>,
    /// Duration in seconds (the stream's, else the file's).
    pub duration: Option<f64>,
    pub audio: Vec<OtherStream>,
    pub subtitles: Vec<OtherStream>,
    /// Mastering display and content light level: the stream's side data, else its
    /// first frame's (HEVC and AV1 carry them in the bitstream).
    pub hdr: HdrMetadata,
}

#[derive(Deserialize)]
struct Probe {
    #[serde(default)]
    streams: Vec<Stream>,
    format: Option<Format>,
    /// The first video frame (`-read_intervals %+#1 -show_frames`), for its side data.
    #[serde(default)]
    frames: Vec<Frame>,
}

#[derive(Deserialize)]
struct Frame {
    stream_index: Option<usize>,
    #[serde(default)]
    side_data_list: Vec<SideData>,
}

#[derive(Deserialize)]
struct Format {
    duration: Option<String>,
}

#[derive(Deserialize, Default)]
struct Disposition {
    #[serde(default)]
    attached_pic: u8,
}

#[derive(Deserialize)]
struct Stream {
    index: usize,
    codec_type: Option<String>,
    codec_name: Option<String>,
    width: Option<u32>,
    height: Option<u32>,
    pix_fmt: Option<String>,
    r_frame_rate: Option<String>,
    avg_frame_rate: Option<String>,
    color_range: Option<String>,
    color_space: Option<String>,
    color_primaries: Option<String>,
    color_transfer: Option<String>,
    field_order: Option<String>,
    nb_frames: Option<String>,
    duration: Option<String>,
    bits_per_raw_sample: Option<String>,
    #[serde(default)]
    disposition: Disposition,
    #[serde(default)]
    side_data_list: Vec<SideData>,
}

/// The `ffprobe` command that [`probe`] runs for `path`.
pub fn probe_args(path: &Path) -> Vec<String> {
    [
        "-v",
        "error",
        "-print_format",
        "json",
        "-show_streams",
        "-show_format",
        "-show_frames",
        "-read_intervals",
        "%+#1",
        "-show_entries",
        "frame=stream_index,side_data_list:stream:format",
        "-i",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain(std::iter::once(file_arg(path)))
    .collect()
}

/// Run `ffprobe` on `path`. Returns the file's streams and the command line run.
/// Errors: ffprobe missing ([`VideoError::Missing`]), a file ffprobe cannot read or
/// without a video stream ([`VideoError::Input`]).
pub fn probe(path: &Path) -> Result<(VideoInfo, String), VideoError> {
    let ffprobe = require("ffprobe", path)?;
    let args = probe_args(path);
    let line = shell_line("ffprobe", &args);
    let mut child = Child::spawn("ffprobe", &ffprobe, &args, Stdio::null(), Stdio::piped())
        .map_err(|source| VideoError::Io {
            path: path.to_path_buf(),
            program: "ffprobe",
            source,
        })?;
    let mut json = Vec::new();
    if let Some(mut out) = child.child.stdout.take() {
        use std::io::Read;
        out.read_to_end(&mut json)
            .map_err(|source| VideoError::Io {
                path: path.to_path_buf(),
                program: "ffprobe",
                source,
            })?;
    }
    let status = child.wait().map_err(|source| VideoError::Io {
        path: path.to_path_buf(),
        program: "ffprobe",
        source,
    })?;
    if !status.success() {
        return Err(VideoError::Input {
            path: path.to_path_buf(),
            message: format!(
                "ffprobe cannot read the file ({}):\n{}",
                super::process::status_text(status),
                child.tail()
            ),
        });
    }
    let info = parse(path, &json)?;
    Ok((info, line))
}

/// The [`VideoInfo`] of ffprobe's JSON output for `path`.
pub fn parse(path: &Path, json: &[u8]) -> Result<VideoInfo, VideoError> {
    let input = |message: String| VideoError::Input {
        path: path.to_path_buf(),
        message,
    };
    let p: Probe = serde_json::from_slice(json)
        .map_err(|e| input(format!("ffprobe's output is not the JSON expected: {e}")))?;
    let kind = |s: &Stream, k: &str| s.codec_type.as_deref() == Some(k);
    let v = p
        .streams
        .iter()
        .find(|s| kind(s, "video") && s.disposition.attached_pic == 0)
        .ok_or_else(|| input("the file has no video stream".into()))?;
    let (width, height) = match (v.width, v.height) {
        (Some(w), Some(h)) if w > 0 && h > 0 => (w, h),
        _ => return Err(input("the video stream has no size".into())),
    };
    let pix = v.pix_fmt.clone().unwrap_or_default();
    if pix.is_empty() {
        return Err(input(
            "ffprobe finds no pixel format for the video stream (a damaged file, or a codec this ffmpeg cannot decode)".into(),
        ));
    }
    let (layout, depth) = layout_and_depth(v, &pix);
    let fps = [&v.r_frame_rate, &v.avg_frame_rate]
        .into_iter()
        .filter_map(|r| r.as_deref().and_then(ratio))
        .next()
        .unwrap_or((0, 0));
    let others = |k: &str| other_streams(&p.streams, k);
    Ok(VideoInfo {
        path: path.to_path_buf(),
        index: v.index,
        codec: v.codec_name.clone().unwrap_or_default(),
        width,
        height,
        fps,
        layout,
        depth,
        range: stream_range(v, &pix),
        matrix: stream_matrix(v),
        pix_fmt: pix,
        color_space: known(&v.color_space),
        color_primaries: known(&v.color_primaries),
        color_transfer: known(&v.color_transfer),
        field_order: known(&v.field_order),
        frames: v
            .nb_frames
            .as_deref()
            .and_then(|n| n.parse().ok())
            .filter(|&n| n > 0),
        duration: seconds(&v.duration).or_else(|| seconds(&p.format.as_ref()?.duration)),
        audio: others("audio"),
        subtitles: others("subtitle"),
        hdr: stream_hdr(v, &p.frames),
    })
}

/// The sample layout and depth of the pixel format `pix`; a narrower depth the
/// stream declares (`bits_per_raw_sample`) wins, since some decoders output wider
/// samples than the stream has (e.g. 10-bit in 16-bit words).
fn layout_and_depth(v: &Stream, pix: &str) -> (Layout, u8) {
    let (layout, mut depth) = pix_fmt::parse(pix);
    if let Some(bits) = v
        .bits_per_raw_sample
        .as_deref()
        .and_then(|b| b.parse::<u8>().ok())
    {
        if (9..depth).contains(&bits) {
            depth = bits;
        }
    }
    (layout, depth)
}

/// A colour tag ffprobe gives, unless it is empty, `unknown` or `reserved`.
fn known(t: &Option<String>) -> Option<String> {
    t.clone()
        .filter(|s| !s.is_empty() && s != "unknown" && s != "reserved")
}

/// The stream's range: its tag, else full for the `yuvj` formats.
fn stream_range(v: &Stream, pix: &str) -> Option<Range> {
    match v.color_range.as_deref() {
        Some("tv") => Some(Range::Limited),
        Some("pc") => Some(Range::Full),
        _ if pix.starts_with("yuvj") => Some(Range::Full),
        _ => None,
    }
}

/// The stream's Y'CbCr matrix, from its colour space tag.
fn stream_matrix(v: &Stream) -> Option<Matrix> {
    match v.color_space.as_deref() {
        Some("bt709") => Some(Matrix::Bt709),
        Some("smpte170m" | "bt470bg" | "fcc") => Some(Matrix::Bt601),
        Some("bt2020nc" | "bt2020c") => Some(Matrix::Bt2020),
        _ => None,
    }
}

/// A duration in seconds ffprobe gives: finite and above 0.
fn seconds(s: &Option<String>) -> Option<f64> {
    s.as_deref()
        .and_then(|d| d.parse::<f64>().ok())
        .filter(|d| d.is_finite() && *d > 0.0)
}

/// The streams of kind `k` (`audio`, `subtitle`): their indices and codecs.
fn other_streams(streams: &[Stream], k: &str) -> Vec<OtherStream> {
    streams
        .iter()
        .filter(|s| s.codec_type.as_deref() == Some(k))
        .map(|s| OtherStream {
            index: s.index,
            codec: s.codec_name.clone().unwrap_or_default(),
        })
        .collect()
}

/// The HDR metadata of the stream `v`: its own side data, else its first frame's.
fn stream_hdr(v: &Stream, frames: &[Frame]) -> HdrMetadata {
    let own = hdr_metadata(&v.side_data_list);
    if !own.is_empty() {
        return own;
    }
    frames
        .iter()
        .find(|f| f.stream_index == Some(v.index))
        .map(|f| hdr_metadata(&f.side_data_list))
        .unwrap_or_default()
}

/// `25/1` → (25, 1); `0/0` and malformed → `None`.
fn ratio(s: &str) -> Option<(u32, u32)> {
    let (n, d) = s.split_once('/')?;
    let (n, d): (u32, u32) = (n.trim().parse().ok()?, d.trim().parse().ok()?);
    (n > 0 && d > 0).then_some((n, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_json_is_read() {
        let json = br#"{"streams":[
            {"index":0,"codec_type":"video","codec_name":"mjpeg","width":1,"height":1,"pix_fmt":"yuvj420p","disposition":{"attached_pic":1}},
            {"index":1,"codec_type":"video","codec_name":"h264","width":96,"height":64,"pix_fmt":"yuv420p10le",
             "r_frame_rate":"30000/1001","color_range":"tv","color_space":"bt709","field_order":"tt","nb_frames":"12","bits_per_raw_sample":"10"},
            {"index":2,"codec_type":"audio","codec_name":"aac"},
            {"index":3,"codec_type":"subtitle","codec_name":"subrip"}],
            "format":{"duration":"0.4"}}"#;
        let i = parse(Path::new("a.mkv"), json).unwrap();
        assert_eq!(
            (i.index, i.width, i.height, i.fps),
            (1, 96, 64, (30000, 1001))
        );
        assert_eq!((i.layout, i.depth), (Layout::Yuv420, 10));
        assert_eq!(
            (i.range, i.matrix),
            (Some(Range::Limited), Some(Matrix::Bt709))
        );
        assert_eq!((i.frames, i.duration), (Some(12), Some(0.4)));
        assert_eq!(i.field_order.as_deref(), Some("tt"));
        assert_eq!(
            i.audio,
            vec![OtherStream {
                index: 2,
                codec: "aac".into()
            }]
        );
        assert_eq!(i.subtitles[0].codec, "subrip");
        let e = parse(
            Path::new("a.mkv"),
            br#"{"streams":[{"index":0,"codec_type":"audio"}]}"#,
        );
        assert!(e.unwrap_err().to_string().contains("no video stream"));
    }
}
