//! `fxrun` with video files through ffmpeg (`-i in.mkv`, `-o out.mp4`): frames, size,
//! depth, the audio and subtitles carried over, and the failures (no ffmpeg, a file
//! ffmpeg rejects, ffmpeg failing while decoding or encoding, Ctrl-C), checked with
//! ffprobe. ffmpeg is required in CI (FX_REQUIRE_GPU set).

use crate::common::cli::{
    assert_no_temporaries, exits_with, fxrun_in, fxrun_line_in, fxrun_with, names, succeeds_in,
};
use crate::common::video::{assert_y4m_header, ffmpeg, frame_count, have_ffmpeg, probe, streams};
use std::path::Path;

const IDENTITY: &str = "EFFECT.id = { OUT = IN }";

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

fn p(d: &Path, name: &str) -> String {
    d.join(name).to_str().unwrap().to_string()
}

/// The temporaries (`.NAME.fxtmp-...`) in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.contains("fxtmp"))
        .collect()
}

/// `in.mkv`: `frames` frames of testsrc2 at 96x64, 25 fps, in `pix_fmt`; with `audio`
/// a 440 Hz sine (AAC) and a SubRip subtitle.
fn make_mkv(d: &Path, name: &str, frames: u32, pix_fmt: &str, audio: bool) {
    let n = frames.to_string();
    let out = p(d, name);
    let mut args = vec!["-f", "lavfi", "-i", "testsrc2=size=96x64:rate=25"];
    let srt = p(d, "subs.srt");
    if audio {
        std::fs::write(&srt, "1\n00:00:00,000 --> 00:00:00,300\nhello\n").unwrap();
        args.extend([
            "-f",
            "lavfi",
            "-i",
            "sine=frequency=440:sample_rate=48000",
            "-i",
            &srt,
        ]);
        args.extend([
            "-map", "0:v", "-map", "1:a", "-map", "2:s", "-c:a", "aac", "-c:s", "srt",
        ]);
    }
    args.extend([
        "-frames:v",
        &n,
        "-t",
        "0.4",
        "-c:v",
        "libx264",
        "-pix_fmt",
        pix_fmt,
        &out,
    ]);
    ffmpeg(&args);
}

/// Luma planes of every frame of a video (8-bit), decoded by ffmpeg (each frame once:
/// `-copyts` keeps ffmpeg from padding a video that starts after its audio).
fn luma(path: &str, w: usize, h: usize) -> Vec<Vec<u8>> {
    let o = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-copyts", "-i", path])
        .args(["-f", "rawvideo", "-pix_fmt", "gray", "-"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o.stdout.chunks(w * h).map(|c| c.to_vec()).collect()
}

#[test]
fn an_mkv_with_audio_becomes_an_mp4_with_its_audio_and_subtitles() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    make_mkv(d, "in.mkv", 10, "yuv420p", true);
    let o = fxrun_line_in(d, "id.fx -i in.mkv -o out.mp4 -v");
    exits_with(
        &o,
        0,
        &[
            "running: ffprobe -v error -print_format json",
            "-f yuv4mpegpipe -",
            "-c:v libx264 -pix_fmt yuv420p",
            "subtitle stream 2 (subrip) is converted to mov_text",
        ],
    );
    let out = d.join("out.mp4");
    let probe = probe(&out);
    let v = streams(&probe, "video");
    assert_eq!(v.len(), 1);
    assert_eq!(v[0]["codec_name"], "h264");
    assert_eq!(v[0]["pix_fmt"], "yuv420p");
    assert_eq!(
        (v[0]["width"].as_u64(), v[0]["height"].as_u64()),
        (Some(96), Some(64))
    );
    assert_eq!(frame_count(&out), 10);
    let a = streams(&probe, "audio");
    assert_eq!(a.len(), 1, "the audio is carried over");
    assert_eq!(a[0]["codec_name"], "aac");
    assert_eq!(streams(&probe, "subtitle")[0]["codec_name"], "mov_text");
    // The pictures are the input's (through H.264 at crf 18): PSNR of the luma.
    let (a, b) = (
        luma(&p(d, "in.mkv"), 96, 64),
        luma(&p(d, "out.mp4"), 96, 64),
    );
    assert_eq!(a.len(), b.len());
    let mse: f64 = a
        .concat()
        .iter()
        .zip(b.concat())
        .map(|(x, y)| (*x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.concat().len() as f64;
    let psnr = 10.0 * (255.0f64 * 255.0 / mse.max(1e-9)).log10();
    eprintln!("luma PSNR of out.mp4 against in.mkv: {psnr:.1} dB");
    assert!(psnr > 35.0, "PSNR {psnr:.1} dB");
    assert_no_temporaries(d);
    // --frames: 5 frames, and the audio of those 5 frames (0.2 s).
    succeeds_in(d, "id.fx -i in.mkv -o part.mkv --frames 2..6");
    assert_eq!(frame_count(&d.join("part.mkv")), 5);
    let probe = crate::common::video::probe(&d.join("part.mkv"));
    let dur: f64 = probe["format"]["duration"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!((0.15..0.3).contains(&dur), "duration {dur}");
    assert_eq!(streams(&probe, "audio").len(), 1);
    assert_eq!(
        streams(&probe, "subtitle").len(),
        1,
        "Matroska keeps SubRip"
    );
}

#[test]
fn a_10_bit_video_gives_a_10_bit_output() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    make_mkv(d, "in10.mkv", 6, "yuv420p10le", false);
    succeeds_in(d, "deinterlace -i in10.mkv -o out.mp4");
    let v = probe(&d.join("out.mp4"));
    assert_eq!(streams(&v, "video")[0]["pix_fmt"], "yuv420p10le");
    assert_eq!(frame_count(&d.join("out.mp4")), 6);
    succeeds_in(d, "id.fx -i in10.mkv -o out.y4m");
    assert_y4m_header(
        &d.join("out.y4m"),
        "YUV4MPEG2 W96 H64 F25:1 Ip A1:1 C420p10",
    );
    // A 10-bit y4m to WebM: VP9 at 10 bits.
    succeeds_in(d, "id.fx -i out.y4m -o out.webm -v");
    let v = probe(&d.join("out.webm"));
    assert_eq!(streams(&v, "video")[0]["codec_name"], "vp9");
    assert_eq!(streams(&v, "video")[0]["pix_fmt"], "yuv420p10le");
    // The depth can be lowered.
    succeeds_in(
        d,
        "id.fx -i in10.mkv -o out8.mp4 --bit-depth 8 --crf 23 --preset veryfast",
    );
    assert_eq!(
        streams(&probe(&d.join("out8.mp4")), "video")[0]["pix_fmt"],
        "yuv420p"
    );
}

#[test]
fn without_ffmpeg_the_error_says_how_to_install_it() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    make_mkv(d, "in.mkv", 3, "yuv420p", false);
    std::fs::write(
        d.join("in.y4m"),
        crate::common::video::y4m(
            "W16 H16 F25:1 C420jpeg",
            8,
            &[vec![vec![100; 256], vec![128; 64], vec![128; 64]]],
        ),
    )
    .unwrap();
    let empty = d.join("no-ffmpeg");
    std::fs::create_dir(&empty).unwrap();
    let env = [("PATH", empty.to_str().unwrap())];
    let o = fxrun_with(d, &["id.fx", "-i", "in.mkv", "-o", "out.y4m"], &env, b"");
    exits_with(
        &o,
        1,
        &["ffprobe was not found on PATH", "apt-get install ffmpeg"],
    );
    let o = fxrun_with(d, &["id.fx", "-i", "in.y4m", "-o", "out.mp4"], &env, b"");
    exits_with(&o, 1, &["out.mp4: ffmpeg was not found on PATH"]);
    assert!(!d.join("out.mp4").exists() && !d.join("out.y4m").exists());
    assert_no_temporaries(d);
}

/// A folder with an `ffmpeg` that runs the real one, except for `mode`: `decode`
/// passes on 20000 bytes of the y4m stream then fails, `encode` reads some of its
/// input then fails. ffprobe is the real one (found further along PATH).
fn fake_ffmpeg(d: &Path, mode: &str) -> String {
    let real = crate::common::video::program_path("ffmpeg");
    let bin = d.join(format!("fake-{mode}"));
    std::fs::create_dir_all(&bin).unwrap();
    let script = format!(
        "#!/bin/sh\n\
         case \"$*\" in\n\
         *'-f yuv4mpegpipe -i pipe:0'*) [ {mode} = encode ] && {{ head -c 30000 >/dev/null; echo 'fake encoder: the disk is on fire' >&2; exit 3; }} ;;\n\
         *'-f yuv4mpegpipe -') [ {mode} = decode ] && {{ '{real}' \"$@\" | head -c 20000; echo 'fake decoder: corrupt macroblock' >&2; exit 1; }} ;;\n\
         esac\n\
         exec '{real}' \"$@\"\n"
    );
    let path = bin.join("ffmpeg");
    std::fs::write(&path, script).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

#[cfg(unix)]
#[test]
fn ffmpeg_failures_are_reported_with_its_stderr_and_leave_no_output() {
    let Some(dir) = setup() else { return };
    let d = dir.path();
    // A file ffprobe rejects.
    std::fs::write(d.join("bad.mkv"), crate::common::rng::Rng(7).bytes(4000)).unwrap();
    let o = fxrun_line_in(d, "id.fx -i bad.mkv -o out.mp4");
    exits_with(
        &o,
        1,
        &[
            "bad.mkv: ffprobe cannot read the file",
            "ffprobe: bad.mkv: Invalid data found",
        ],
    );
    assert!(!d.join("out.mp4").exists());
    // ffmpeg fails while decoding: the input is rejected (exit 1); while encoding:
    // an output fault (exit 2). Either way with its stderr, and the old output kept.
    make_mkv(d, "in.mkv", 10, "yuv420p", true);
    std::fs::write(d.join("out.mp4"), b"the old output").unwrap();
    for (mode, status, says) in [
        (
            "decode",
            1,
            [
                "in.mkv: ffmpeg could not decode the video (exit status 1)",
                "ffmpeg: fake decoder: corrupt macroblock",
            ],
        ),
        (
            "encode",
            2,
            [
                "out.mp4: ", // on writing or on finishing: ffmpeg may read it all first
                "ffmpeg: fake encoder: the disk is on fire",
            ],
        ),
    ] {
        let path = fake_ffmpeg(d, mode);
        let args = ["id.fx", "-i", "in.mkv", "-o", "out.mp4"];
        exits_with(
            &fxrun_with(d, &args, &[("PATH", &path)], b""),
            status,
            &says,
        );
        assert_eq!(std::fs::read(d.join("out.mp4")).unwrap(), b"the old output");
        assert_no_temporaries(d);
    }
    // Options ffmpeg would refuse are refused before it starts (exit 1).
    for (opt, val, says) in [
        (
            "--codec",
            "no-such-codec",
            "this ffmpeg has no such encoder",
        ),
        ("--pix-fmt", "rgb24", "the encoder libx264 takes"),
        ("--preset", "warp9", "libx264 takes ultrafast"),
    ] {
        let o = fxrun_in(d, &["id.fx", "-i", "in.mkv", "-o", "out.mp4", opt, val]);
        exits_with(&o, 1, &[says]);
    }
    assert_eq!(std::fs::read(d.join("out.mp4")).unwrap(), b"the old output");
}

/// Ctrl-C (SIGINT to fxrun alone) while it encodes: exit 130, no output, no
/// temporary, no ffmpeg left running.
#[cfg(unix)]
#[test]
fn interrupting_a_video_run_ends_ffmpeg_and_writes_nothing() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let Some(dir) = setup() else { return };
    let d = dir.path();
    let frame = [vec![90u16; 64 * 64], vec![128; 32 * 32], vec![128; 32 * 32]];
    let frames = vec![frame.to_vec(); 5];
    let stream = crate::common::video::y4m("W64 H64 F25:1 Ip A1:1 C420jpeg", 8, &frames);
    let mut child = Command::new(env!("CARGO_BIN_EXE_fxrun"))
        .args(["id.fx", "-i", "-", "-o", "out.mp4"])
        .current_dir(d)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(&stream).unwrap();
    // The encoder's temporary exists once fxrun is about to run (its Ctrl-C handler
    // is installed before); the stream is left open, fxrun waiting on it.
    let t0 = std::time::Instant::now();
    while temporaries(d).is_empty() {
        assert!(t0.elapsed().as_secs() < 60, "the encoder did not start");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    // fxrun sees the stop between two frames: more frames come until it has ended
    // (its decoder would otherwise wait on the open stream), then the end.
    let one = crate::common::video::y4m("W64 H64 F25:1 Ip A1:1 C420jpeg", 8, &frames[..1]);
    let frame_bytes = &one[one.iter().position(|&b| b == b'\n').unwrap() + 1..];
    let t0 = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(t0.elapsed().as_secs() < 120, "fxrun did not stop");
        if stdin.write_all(frame_bytes).is_err() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("out.mp4 was not written"), "{err}");
    assert!(!d.join("out.mp4").exists());
    assert_no_temporaries(d);
    // No process has anything of this folder on its command line any more.
    let dir_name = d.to_string_lossy().into_owned();
    let left: Vec<String> = std::fs::read_dir("/proc")
        .map(|rd| {
            rd.filter_map(|e| std::fs::read(e.ok()?.path().join("cmdline")).ok())
                .map(|c| String::from_utf8_lossy(&c).replace('\0', " "))
                .filter(|c| c.contains(&dir_name) && c.contains("ffmpeg"))
                .collect()
        })
        .unwrap_or_default();
    assert!(left.is_empty(), "still running: {left:?}");
}
