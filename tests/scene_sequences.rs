//! Rendered sequences through `fxrun` (src/app/scene_sequence.rs): `--scene` with
//! `--frames A..B` or `--time SECONDS`. Frame n is rendered at n / fps and depends
//! on n alone, so a frame of a sequence, the same frame rendered alone with
//! `--time`, and the same frame of a slice are byte-identical (also through a
//! temporal effect that reads the previous frame), and the sequence feeds
//! temporal effects like a file sequence.

mod common;

use common::cli::{assert_same_file, code, fxrun, read, stderr};
use std::path::Path;

fn gpu() -> bool {
    common::engine().is_some()
}

fn ok(args: &[&str]) {
    let o = fxrun(args);
    assert_eq!(code(&o), 0, "fxrun {}: {}", args.join(" "), stderr(&o));
}

/// `EFFECTS... --scene builtin:room --camera CAMERA --size SIZE MORE...`: the
/// built-in room seen from a moving camera.
fn room<'a>(effects: &[&'a str], camera: &'a str, size: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let scene = [
        "--scene",
        "builtin:room",
        "--camera",
        camera,
        "--size",
        size,
    ];
    [effects, &scene[..], more].concat()
}

#[test]
fn a_frame_of_a_sequence_equals_it_rendered_alone_and_in_a_slice() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    let base = room(&["tonemap"], "orbit:period=2", "96x64", &["--fps", "24"]);
    let seq = format!("{d}/seq/%04d.png");
    ok(&[&base[..], &["--frames", "0..4", "-o", &seq]].concat());
    for n in 0..=4 {
        assert!(Path::new(&format!("{d}/seq/{n:04}.png")).exists());
    }
    // frame 3 at 3/24 s alone
    let alone = format!("{d}/alone.png");
    ok(&[&base[..], &["--time", "0.125", "-o", &alone]].concat());
    assert_same_file(&alone, format!("{d}/seq/0003.png"));
    // a slice 3..4 on "another machine"
    let slice = format!("{d}/slice/%04d.png");
    ok(&[&base[..], &["--frames", "3..4", "-o", &slice]].concat());
    for n in 3..=4 {
        assert_same_file(
            format!("{d}/slice/{n:04}.png"),
            format!("{d}/seq/{n:04}.png"),
        );
    }
    // the camera moves: consecutive frames differ
    assert_ne!(
        read(format!("{d}/seq/0000.png")),
        read(format!("{d}/seq/0001.png"))
    );
}

#[test]
fn a_rendered_sequence_feeds_temporal_effects_with_history() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    // frame_blend mixes IN[-1] and IN: frame 2 of the sequence needs frame 1,
    // which a slice starting at 2 renders first (the chain's history)
    let base = room(&["frame_blend", "tonemap"], "orbit:period=1", "80x48", &[]);
    let (all, part) = (format!("{d}/all/%02d.png"), format!("{d}/part/%02d.png"));
    ok(&[&base[..], &["--frames", "0..3", "-o", &all]].concat());
    ok(&[&base[..], &["--frames", "2..3", "-o", &part]].concat());
    for n in 2..=3 {
        assert_same_file(
            format!("{d}/part/{n:02}.png"),
            format!("{d}/all/{n:02}.png"),
        );
    }
    let t = format!("{d}/t.png");
    ok(&[&base[..], &["--time", "0.1", "-o", &t]].concat());
    assert_same_file(&t, format!("{d}/all/03.png"));
    // the blend differs from the plain frame (the previous frame is mixed in)
    let plain = format!("{d}/plain.png");
    let tonemap = room(&["tonemap"], "orbit:period=1", "80x48", &[]);
    ok(&[&tonemap[..], &["--time", "0.1", "-o", &plain]].concat());
    assert_ne!(read(&plain), read(&t));
}

#[test]
fn a_rendered_sequence_streams_y4m_on_stdout() {
    if !gpu() {
        return;
    }
    let scene = ["tonemap", "--scene", "builtin:room", "--size", "64x48"];
    let o = fxrun(&[&scene[..], &["--frames", "0..2", "--fps", "25", "-o", "-"]].concat());
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let header = String::from_utf8_lossy(&o.stdout[..40]).into_owned();
    assert!(header.starts_with("YUV4MPEG2 W64 H48 F25:1"), "{header}");
    assert_eq!(o.stdout.windows(6).filter(|w| w == b"FRAME\n").count(), 3);
}

#[test]
fn time_and_frame_options_are_checked() {
    for (args, want) in [
        (&["--time", "-1"][..], "must be 0 or more seconds"),
        (&["--time", "1", "--frames", "0..2"][..], "give one of them"),
        (&["--frames", "4.."][..], "needs its last frame"),
        (
            &["--frames", "0..2", "--gbuffer", "g"][..],
            "--gbuffer writes one frame",
        ),
        (&["--frames", "0..2", "--fps", "0"][..], "--fps 0"),
        (
            &["--frames", "0..2", "--camera", "orbit:period=0"][..],
            "period",
        ),
    ] {
        let mut a = vec!["--scene", "builtin:room", "-o", "x/%04d.png"];
        a.extend_from_slice(args);
        let o = fxrun(&a);
        assert_eq!(code(&o), 1, "{a:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{a:?}: {}", stderr(&o));
    }
}

#[test]
fn a_rendered_sequence_writes_y4m_and_video_files() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    let base = room(
        &["tonemap"],
        "orbit:period=1",
        "64x48",
        &["--frames", "0..5"],
    );
    let y4m = format!("{d}/room.y4m");
    ok(&[&base[..], &["-o", &y4m]].concat());
    let bytes = common::video::assert_y4m_header(Path::new(&y4m), "YUV4MPEG2 W64 H48 F30:1");
    assert_eq!(bytes.windows(6).filter(|w| w == b"FRAME\n").count(), 6);
    // a video file through ffmpeg (CI installs it; without it this must fail)
    let mp4 = format!("{d}/room.mp4");
    ok(&[&base[..], &["-o", &mp4]].concat());
    let probe = std::process::Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-count_frames",
            "-show_entries",
            "stream=width,height,nb_read_frames",
            "-of",
            "csv=p=0",
            &mp4,
        ])
        .output()
        .expect("ffprobe (apt-get install ffmpeg)");
    assert_eq!(String::from_utf8_lossy(&probe.stdout).trim(), "64,48,6");
    // a whole file cannot be resumed: an existing one is kept and the run skipped
    // (as for an image sequence's y4m output); the file is untouched
    let before = std::fs::read(&y4m).unwrap();
    let o = fxrun(&[&base[..], &["--fps", "10", "-o", &y4m, "--skip-existing"]].concat());
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("exists already; nothing to do"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&y4m).unwrap(), before);
}

#[test]
fn gbuffer_with_time_writes_that_frames_motion() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    let motion = |gb: &str| {
        let img = fxgraph::io::load_image(
            &Path::new(d).join(gb).join("motion.exr"),
            &Default::default(),
        )
        .expect("motion.exr");
        let fxgraph::io::Pixels::F32(px) = img.pixels else {
            panic!("motion.exr holds floats")
        };
        (0..px.len() / 4)
            .map(|i| (px[4 * i], px[4 * i + 1]))
            .collect::<Vec<_>>()
    };
    // a turntable (orbit about +Y, elevation 0): between t - 1/30 and t the camera
    // turns 360 / 8 / 30 = 1.5 degrees, so pixels move sideways, hardly up or down
    let turning = room(&["tonemap"], "orbit:period=8,elevation=0", "96x54", &[]);
    let gb = format!("{d}/gb");
    ok(&[
        &turning[..],
        &[
            "--time",
            "0.5",
            "--gbuffer",
            &gb,
            "-o",
            &format!("{d}/t.png"),
        ],
    ]
    .concat());
    let m = motion("gb");
    let moving = m.iter().filter(|(x, _)| x.abs() > 0.1).count();
    assert!(
        moving > m.len() * 9 / 10,
        "{moving} of {} pixels move",
        m.len()
    );
    // perspective gives the floor and ceiling some vertical motion; on the whole
    // the motion is sideways
    let (sx, sy) = m
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x.abs(), b + y.abs()));
    assert!(sx > 4.0 * sy, "mean |x| {sx} against mean |y| {sy}");
    // the still (no --time) of the same camera has no motion at all
    let still = format!("{d}/still");
    ok(&[
        &turning[..],
        &["--gbuffer", &still, "-o", &format!("{d}/s.png")],
    ]
    .concat());
    assert!(motion("still").iter().all(|&(x, y)| x == 0.0 && y == 0.0));
}
