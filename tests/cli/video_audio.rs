//! The audio of an input video in each output container (issue 29, point 3): every
//! container (mp4, mov, mkv, webm) × audio codec (aac, flac, pcm_s16le, opus, mp3,
//! ac3) written by `fxrun` and read back with ffprobe (the reference: the streams
//! of the file as FFmpeg sees them). A codec the container holds is copied, any
//! other becomes AAC (mp4, mov) or Opus (webm); Matroska keeps all. Before the fix,
//! FLAC into MP4 stopped FFmpeg 5.1 at the header, after the first frames.
//!
//! To keep the run short, one input carries the six codecs as six audio streams
//! (64x64, 6 frames, 0.24 s of a 440 Hz sine): four runs of fxrun cover the 24
//! cases, each stream decoded back and checked for its length and pitch; the
//! issue's own case (one FLAC stream, 24 frames, `deinterlace`) runs once more.

use crate::common::cli::{assert_no_temporaries, exits_with, fxrun_line_in};
use crate::common::video::{ffmpeg, frame_count, have_ffmpeg, probe, streams};
use std::path::Path;

const IDENTITY: &str = "EFFECT.id = { OUT = IN }";

/// The input's audio streams: (ffprobe codec name, the ffmpeg encoder made it).
const CODECS: [(&str, &str); 6] = [
    ("aac", "aac"),
    ("flac", "flac"),
    ("pcm_s16le", "pcm_s16le"),
    ("opus", "libopus"),
    ("mp3", "libmp3lame"),
    ("ac3", "ac3"),
];

/// A temporary folder with `id.fx`, or `None` without a GPU or ffmpeg (in CI: a
/// panic).
fn setup() -> Option<tempfile::TempDir> {
    let dir = crate::common::gpu_scratch()?;
    if !have_ffmpeg() {
        return None;
    }
    std::fs::write(dir.path().join("id.fx"), IDENTITY).unwrap();
    Some(dir)
}

/// `name`: `frames` frames of testsrc2 at 64x64, 25 fps, H.264, with one audio
/// stream per encoder of `encoders` (the same 440 Hz sine, 48 kHz, as long as the
/// video; the sources end by `duration`: `-frames:v`/`-t` would cut the audio
/// encoders' last packets off).
fn make_mkv(d: &Path, name: &str, frames: u32, encoders: &[&str]) {
    let out = d.join(name);
    let seconds = frames as f64 / 25.0;
    let video = format!("testsrc2=size=64x64:rate=25:duration={seconds}");
    let audio = format!("sine=frequency=440:sample_rate=48000:duration={seconds}");
    let mut args: Vec<String> = vec![
        "-f".into(),
        "lavfi".into(),
        "-i".into(),
        video,
        "-f".into(),
        "lavfi".into(),
        "-i".into(),
        audio,
        "-map".into(),
        "0:v".into(),
    ];
    for (k, e) in encoders.iter().enumerate() {
        args.extend([
            "-map".into(),
            "1:a".into(),
            format!("-c:a:{k}"),
            e.to_string(),
        ]);
    }
    for a in [
        "-c:v",
        "libx264",
        "-pix_fmt",
        "yuv420p",
        out.to_str().unwrap(),
    ] {
        args.push(a.to_string());
    }
    ffmpeg(&args.iter().map(String::as_str).collect::<Vec<_>>());
}

/// The `k`-th audio stream of a file decoded by ffmpeg: mono 16-bit samples at
/// 48 kHz.
fn decoded(path: &Path, k: usize) -> Vec<i16> {
    let o = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(path)
        .args(["-map", &format!("0:a:{k}"), "-ac", "1", "-ar", "48000"])
        .args(["-f", "s16le", "-"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o.stdout
        .chunks_exact(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect()
}

/// The frequency of a sine from its zero crossings, over the middle 80 % of the
/// samples (the ends hold the encoders' priming and padding).
fn frequency(samples: &[i16]) -> f64 {
    let (a, b) = (samples.len() / 10, samples.len() * 9 / 10);
    let part = &samples[a..b];
    let crossings = part.windows(2).filter(|w| (w[0] < 0) != (w[1] < 0)).count();
    crossings as f64 / 2.0 / (part.len() as f64 / 48_000.0)
}

/// The codec ffprobe reads for each stream of the input's six after writing `ext`.
fn expected(ext: &str) -> [&'static str; 6] {
    match ext {
        "mp4" => ["aac", "aac", "aac", "opus", "mp3", "ac3"],
        "mov" => ["aac", "aac", "pcm_s16le", "aac", "mp3", "ac3"],
        "mkv" => ["aac", "flac", "pcm_s16le", "opus", "mp3", "ac3"],
        "webm" => ["opus"; 6],
        _ => unreachable!(),
    }
}

#[test]
fn every_container_gets_every_common_audio_codec_copied_or_converted() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let encoders: Vec<&str> = CODECS.iter().map(|c| c.1).collect();
    make_mkv(d, "six.mkv", 6, &encoders);
    let input = probe(&d.join("six.mkv"));
    let made: Vec<&str> = streams(&input, "audio")
        .iter()
        .map(|s| s["codec_name"].as_str().unwrap_or(""))
        .collect();
    let names: Vec<&str> = CODECS.iter().map(|c| c.0).collect();
    assert_eq!(made, names, "the input's audio streams");
    let mut right = 0;
    let (mut worst_extra, mut worst_pitch) = (0usize, 0.0f64);
    let mut wrong = Vec::new();
    for (ext, video) in [
        ("mp4", "h264"),
        ("mov", "h264"),
        ("mkv", "h264"),
        ("webm", "vp9"),
    ] {
        let out = format!("out.{ext}");
        let o = fxrun_line_in(d, &format!("id.fx -i six.mkv -o {out} -v"));
        // a note for each stream converted
        let notes: Vec<String> = expected(ext)
            .iter()
            .zip(names.iter())
            .enumerate()
            .filter(|(_, (want, had))| **want != **had)
            .map(|(k, (_, had))| format!("audio stream {} ({had}) is converted", k + 1))
            .collect();
        exits_with(&o, 0, &notes.iter().map(String::as_str).collect::<Vec<_>>());
        let p = probe(&d.join(&out));
        let v = streams(&p, "video");
        assert_eq!(v.len(), 1, "{out}: one video stream");
        assert_eq!(v[0]["codec_name"], video, "{out}");
        assert_eq!(frame_count(&d.join(&out)), 6, "{out}");
        let got: Vec<&str> = streams(&p, "audio")
            .iter()
            .map(|s| s["codec_name"].as_str().unwrap_or(""))
            .collect();
        assert_eq!(got.len(), 6, "{out}: six audio streams: {got:?}");
        for (k, (g, w)) in got.iter().zip(expected(ext)).enumerate() {
            if *g == w {
                right += 1;
            } else {
                wrong.push(format!("{out}: stream {k} ({}) is {g}, not {w}", names[k]));
            }
        }
        // each stream is the input's sine, whole: at least the clip's 11,520
        // samples and at most two AAC frames (2,048 samples) more (encoder
        // priming and padding of the last frame), and 440 Hz by its zero
        // crossings, within 1 %
        for k in 0..6 {
            let a = decoded(&d.join(&out), k);
            let (n, f) = (a.len(), frequency(&a));
            worst_extra = worst_extra.max(n.saturating_sub(11_520));
            worst_pitch = worst_pitch.max((f / 440.0 - 1.0).abs());
            assert!(
                (11_520..=11_520 + 2_048).contains(&n),
                "{out} stream {k}: {n} samples"
            );
            assert!(
                (f / 440.0 - 1.0).abs() < 0.01,
                "{out} stream {k}: {f:.1} Hz"
            );
        }
    }
    eprintln!(
        "audio codec as expected in {right} of 24 container x codec cases; at most {worst_extra} samples over the clip's 11520, pitch at most {:.2} % off 440 Hz",
        worst_pitch * 100.0
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert_no_temporaries(d);
}

/// The run: an MKV with FLAC audio into MP4, more frames than FFmpeg 5.1
/// took before it stopped (18).
#[test]
fn flac_in_an_mkv_becomes_aac_in_an_mp4_of_every_frame() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    make_mkv(d, "flac.mkv", 24, &["flac"]);
    let o = fxrun_line_in(d, "deinterlace -i flac.mkv -o out.mp4 -v");
    exits_with(
        &o,
        0,
        &[
            "audio stream 1 (flac) is converted to aac for .mp4",
            "-c:a:0 aac",
        ],
    );
    let p = probe(&d.join("out.mp4"));
    assert_eq!(streams(&p, "audio").len(), 1, "{p}");
    assert_eq!(streams(&p, "audio")[0]["codec_name"], "aac");
    assert_eq!(frame_count(&d.join("out.mp4")), 24);
    let a = decoded(&d.join("out.mp4"), 0);
    let (n, f) = (a.len() as f64, frequency(&a));
    eprintln!("out.mp4: {n} samples (0.96 s: 46080), {f:.1} Hz");
    assert!((n / 46_080.0 - 1.0).abs() < 0.05, "{n} samples");
    assert!((f / 440.0 - 1.0).abs() < 0.02, "{f:.1} Hz");
}
