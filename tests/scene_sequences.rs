//! Rendered sequences through `fxrun` (src/app/scene_sequence.rs): `--scene` with
//! `--frames A..B` or `--time SECONDS`. Frame n is rendered at n / fps and depends
//! on n alone, so a frame of a sequence, the same frame rendered alone with
//! `--time`, and the same frame of a slice are byte-identical (also through a
//! temporal effect that reads the previous frame), and the sequence feeds
//! temporal effects like a file sequence.

use crate::common;

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
    use common::brdf::OracleCamera;
    use fxgraph::scene::{CameraPath, Scene};
    use glam::Vec3;
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    let floats = |gb: &str, name: &str| {
        let path = Path::new(d).join(gb).join(name);
        let img = fxgraph::io::load_image(&path, &Default::default()).expect("an EXR");
        let fxgraph::io::Pixels::F32(px) = img.pixels else {
            panic!("{name} holds floats")
        };
        px
    };
    let (w, h) = (96u32, 54u32);
    let spec = "orbit:period=8,elevation=0";
    let turning = room(&["tonemap"], spec, "96x54", &[]);
    ok(&[
        &turning[..],
        &[
            "--time",
            "0.5",
            "--gbuffer",
            &format!("{d}/gb"),
            "-o",
            &format!("{d}/t.png"),
        ],
    ]
    .concat());
    let (motion, depth) = (floats("gb", "motion.exr"), floats("gb", "depth.exr"));
    // Reference (tolerance 0.05 px, as tests/motion_vectors.rs; Rg16Float keeps
    // about 1e-3 px here): each pixel's surface point (its ray at the linear view depth of
    // depth.exr) projected by the orbit's cameras at t = 0.5 and t - 1/30.
    let scene = Scene::load("builtin:room").unwrap();
    let path = CameraPath::parse(Some(spec), &scene).unwrap();
    let cam = |t: f64| OracleCamera::of(&path.at(&scene, None, t), w, h);
    let (now, before) = (cam(0.5), cam(0.5 - 1.0 / 30.0));
    let project = |c: &OracleCamera, x: Vec3| {
        let f = (c.target - c.eye).normalize();
        let s = f.cross(c.up).normalize();
        let u = s.cross(f);
        let (v, t) = (x - c.eye, (c.fov_y * 0.5).tan());
        let ndc = (
            v.dot(s) / (v.dot(f) * c.aspect * t),
            v.dot(u) / (v.dot(f) * t),
        );
        (
            (ndc.0 + 1.0) * 0.5 * w as f32,
            (1.0 - ndc.1) * 0.5 * h as f32,
        )
    };
    // pixels without geometry hold the far distance; their motion is that of
    // directions (points at infinity), the camera's turn alone
    let far = depth.iter().step_by(4).fold(0.0f32, |a, &b| a.max(b));
    let z = |x: u32, y: u32| depth[4 * (y * w + x) as usize];
    let (mut checked, mut worst) = (0, 0.0f32);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            // interior pixels of a surface (no depth edge among the neighbours)
            let dz = z(x, y);
            let flat = [(0, 1), (2, 1), (1, 0), (1, 2)]
                .iter()
                .all(|&(i, j)| (z(x + i - 1, y + j - 1) - dz).abs() < 0.01 * dz);
            if !(dz.is_finite() && dz > 0.0 && flat) {
                continue;
            }
            let (eye, dir) = now.ray(x, y);
            let f = (now.target - now.eye).normalize();
            let point = if dz >= far {
                eye + dir * 1.0e5
            } else {
                eye + dir * (dz / dir.dot(f))
            };
            let (px, py) = project(&before, point);
            let want = (x as f32 + 0.5 - px, y as f32 + 0.5 - py);
            let i = 4 * (y * w + x) as usize;
            worst = worst.max(
                (motion[i] - want.0)
                    .abs()
                    .max((motion[i + 1] - want.1).abs()),
            );
            checked += 1;
        }
    }
    assert!(checked > (w * h / 4) as usize, "{checked} interior pixels");
    assert!(
        worst < 0.05,
        "motion.exr against the projected displacement: {worst} px"
    );
    // the still (no --time) of the same camera has no motion at all
    ok(&[
        &turning[..],
        &[
            "--gbuffer",
            &format!("{d}/still"),
            "-o",
            &format!("{d}/s.png"),
        ],
    ]
    .concat());
    let still = floats("still", "motion.exr");
    assert!(still.chunks(4).all(|m| m[0] == 0.0 && m[1] == 0.0));
}

/// `--time` with `--gbuffer` and no `-o` (issue 29, point 4) writes that frame's
/// G-buffer, as a still with `--gbuffer` alone does: byte for byte the G-buffer of
/// the same frame rendered with `-o` (whose motion.exr the test above checks
/// against the projected displacement), with and without effects named, and
/// nothing else.
#[test]
fn gbuffer_with_time_needs_no_output() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path().to_str().unwrap();
    let spec = "orbit:period=8,elevation=0";
    let gbuffer = |name: &str| {
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(Path::new(d).join(name))
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (
                    p.file_name().unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                )
            })
            .collect();
        files.sort();
        files
    };
    let with_o = format!("{d}/with_o");
    let t_png = format!("{d}/t.png");
    ok(&room(
        &["tonemap"],
        spec,
        "96x54",
        &["--time", "0.5", "--gbuffer", &with_o, "-o", &t_png],
    ));
    let reference = gbuffer("with_o");
    assert!(
        reference.iter().any(|(n, _)| n == "motion.exr"),
        "{:?}",
        reference.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for (effects, name) in [(&["tonemap"][..], "alone"), (&[][..], "bare")] {
        let gb = format!("{d}/{name}");
        ok(&room(
            effects,
            spec,
            "96x54",
            &["--time", "0.5", "--gbuffer", &gb],
        ));
        let got = gbuffer(name);
        assert_eq!(
            got.iter().map(|f| &f.0).collect::<Vec<_>>(),
            reference.iter().map(|f| &f.0).collect::<Vec<_>>()
        );
        for (a, b) in got.iter().zip(&reference) {
            assert!(a.1 == b.1, "{name}/{} differs from the run with -o", a.0);
        }
    }
    // nothing but the G-buffers and the one image of the run with -o
    let mut names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["alone", "bare", "t.png", "with_o"]);
    // --frames still needs -o, and still refuses --gbuffer
    let o = fxrun(&room(&[], spec, "96x54", &["--frames", "0..2"]));
    assert_eq!(code(&o), 1, "{}", stderr(&o));
}
