//! Video test helpers: ffmpeg and ffprobe (the independent reference; required in CI,
//! where FX_REQUIRE_GPU is set), y4m streams of any depth written and read without
//! fxgraph's own reader, and probes of outputs.
#![allow(dead_code)]

use super::tools::checked;
use std::path::Path;
use std::process::Command;

/// Whether ffmpeg and ffprobe can be run. Missing: a panic when FX_REQUIRE_GPU is set
/// (CI installs ffmpeg), else `false` with a message (the test is skipped, loudly).
pub fn have_ffmpeg() -> bool {
    let ok = |p: &str| {
        Command::new(p)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if ok("ffmpeg") && ok("ffprobe") {
        return true;
    }
    if std::env::var_os("FX_REQUIRE_GPU").is_some() {
        panic!("FX_REQUIRE_GPU is set but ffmpeg/ffprobe are not on PATH (apt-get install ffmpeg)");
    }
    eprintln!("SKIPPED: ffmpeg/ffprobe not on PATH");
    false
}

/// Run `ffmpeg -v error -y ARGS`; panics with its stderr when it fails.
pub fn ffmpeg(args: &[&str]) {
    let mut cmd = Command::new("ffmpeg");
    cmd.args(["-v", "error", "-y"]).args(args);
    checked(&mut cmd, &format!("ffmpeg {args:?}"), "run ffmpeg");
}

/// `ffprobe -show_streams -show_format` of a file, as JSON.
pub fn probe(path: &Path) -> serde_json::Value {
    let mut cmd = Command::new("ffprobe");
    cmd.args("-v error -print_format json -show_streams -show_format".split(' '))
        .arg(path);
    let o = checked(
        &mut cmd,
        &format!("ffprobe {}", path.display()),
        "run ffprobe",
    );
    serde_json::from_slice(&o.stdout).expect("ffprobe JSON")
}

/// The streams of a probe of `kind` (`video`, `audio`, `subtitle`).
pub fn streams<'a>(probe: &'a serde_json::Value, kind: &str) -> Vec<&'a serde_json::Value> {
    probe["streams"]
        .as_array()
        .map(|a| a.iter().filter(|s| s["codec_type"] == kind).collect())
        .unwrap_or_default()
}

/// Frames of the first video stream, decoded and counted by ffprobe.
pub fn frame_count(path: &Path) -> u64 {
    let mut cmd = Command::new("ffprobe");
    cmd.args(
        "-v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
         -of default=nokey=1:noprint_wrappers=1"
            .split_whitespace(),
    )
    .arg(path);
    let o = checked(
        &mut cmd,
        &format!("ffprobe {}", path.display()),
        "run ffprobe",
    );
    let text = String::from_utf8_lossy(&o.stdout);
    text.trim()
        .parse()
        .unwrap_or_else(|_| panic!("frame count of {}: {text:?}", path.display()))
}

/// Asserts that the y4m file at `path` starts with the header `start`
/// (`YUV4MPEG2 W.. H..`, as far as given); returns the file's bytes.
#[track_caller]
pub fn assert_y4m_header(path: &Path, start: &str) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(80)]);
    assert!(
        bytes.starts_with(start.as_bytes()),
        "{}: {head}",
        path.display()
    );
    bytes
}

/// A y4m stream: `header` (without `YUV4MPEG2 ` and the newline) and frames of planes
/// of samples (one byte each at 8 bits, two little-endian bytes above).
pub fn y4m(header: &str, depth: u8, frames: &[Vec<Vec<u16>>]) -> Vec<u8> {
    let mut s = format!("YUV4MPEG2 {header}\n").into_bytes();
    for f in frames {
        s.extend_from_slice(b"FRAME\n");
        for plane in f {
            for &v in plane {
                if depth > 8 {
                    s.extend_from_slice(&v.to_le_bytes());
                } else {
                    s.push(v as u8);
                }
            }
        }
    }
    s
}

/// A y4m stream read back: its header line (without the newline) and each frame's
/// `samples` samples (all planes in order); `FRAME` lines without parameters.
pub fn read_y4m(bytes: &[u8], depth: u8, samples: usize) -> (String, Vec<Vec<u16>>) {
    let end = bytes.iter().position(|&b| b == b'\n').expect("header line");
    let header = String::from_utf8_lossy(&bytes[..end]).into_owned();
    let size = if depth > 8 { 2 } else { 1 };
    let mut frames = Vec::new();
    let mut rest = &bytes[end + 1..];
    while !rest.is_empty() {
        assert!(
            rest.starts_with(b"FRAME\n"),
            "frame {}: a FRAME line",
            frames.len()
        );
        assert!(
            rest.len() >= 6 + samples * size,
            "frame {} truncated",
            frames.len()
        );
        let (body, tail) = rest[6..].split_at(samples * size);
        frames.push(if depth > 8 {
            body.chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect()
        } else {
            body.iter().map(|&b| b as u16).collect()
        });
        rest = tail;
    }
    (header, frames)
}

/// Samples of one frame of a 4:2:0 stream (`w x h` luma, two `ceil(w/2) x ceil(h/2)`
/// chroma planes), of 4:4:4 (three full planes) and of mono (luma only).
pub fn samples_420(w: usize, h: usize) -> usize {
    w * h + 2 * w.div_ceil(2) * h.div_ceil(2)
}

/// The full path of a program on PATH (for scripts that must call the real one).
pub fn program_path(name: &str) -> String {
    std::env::var_os("PATH")
        .and_then(|p| {
            std::env::split_paths(&p)
                .map(|d| d.join(name))
                .find(|f| f.is_file())
        })
        .unwrap_or_else(|| panic!("{name} is not on PATH"))
        .to_string_lossy()
        .into_owned()
}
