//! `fxrun --view` on a real X server (Xvfb; lavapipe presents through its
//! software WSI): the scripted screenshot of an image, a sequence frame and a
//! scene equals a normal run's output of the same frame; a parameter changed
//! through the panel's code path (`--view-do K:set`) changes the next frame as
//! `--set` would; a reload after an edited shader, and after a broken one (the last
//! image stays, the error is shown); an inspected pass equals a run of the effect
//! up to that pass; the X display shows the window's image as the output; no
//! display is exit 1 with a clear message.
//!
//! References: the normal runs of the same fxrun binary (the files a run writes),
//! and ImageMagick's `import -window root` for what the display shows. Skipped
//! without an adapter or an X display, failed under FX_REQUIRE_GPU=1.

mod common;

use common::cli::{code, stderr, stdout};
use common::display::{display, fxrun_view, grab_screen, window_names};
use fxgraph::io::{load_image, LoadOptions, Pixels};
use std::io::{BufRead as _, BufReader, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A display and an adapter, or `None` (skipped). The engine's lock is held while
/// the test runs, so the viewers of the tests run one at a time.
fn setup() -> Option<(
    String,
    std::sync::MutexGuard<'static, fxgraph::gpu::executor::Engine>,
)> {
    let d = display()?;
    let gpu = common::engine()?;
    Some((d, gpu))
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// A 96x64 test photo with bright spots (so glow has something to do).
fn photo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let img = common::pattern_u8(96, 64);
    fxgraph::io::save_image(&path, 96, 64, &img.pixels, &Default::default()).unwrap();
    path
}

/// `fxrun ARGS` (a normal run) in `dir`, which must succeed.
fn normal(dir: &Path, args: &[&str]) {
    let o = common::cli::fxrun_in(dir, args);
    assert_eq!(code(&o), 0, "fxrun {args:?}: {}", stderr(&o));
}

/// `fxrun ARGS --view ...` in `dir` on the display, which must succeed.
fn view(d: &str, dir: &Path, args: &[&str]) -> std::process::Output {
    let o = fxrun_view(d, dir, args);
    assert_eq!(code(&o), 0, "fxrun {args:?}: {}", stderr(&o));
    o
}

fn pixels(path: &Path) -> (u32, u32, Pixels) {
    let img = load_image(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (img.width, img.height, img.pixels)
}

/// The two files hold the same image, sample for sample.
fn assert_same_image(a: &Path, b: &Path) {
    let (pa, pb) = (pixels(a), pixels(b));
    assert_eq!(
        (pa.0, pa.1),
        (pb.0, pb.1),
        "{} and {} differ in size",
        a.display(),
        b.display()
    );
    assert!(pa.2 == pb.2, "{} and {} differ", a.display(), b.display());
}

/// Largest difference in 8-bit steps and the share of samples that differ.
fn diff_u8(a: &Path, b: &Path) -> (u8, f64) {
    let (Pixels::U8(x), Pixels::U8(y)) = (pixels(a).2, pixels(b).2) else {
        panic!("8-bit images expected");
    };
    assert_eq!(x.len(), y.len());
    let max = x
        .iter()
        .zip(&y)
        .map(|(p, q)| p.abs_diff(*q))
        .max()
        .unwrap_or(0);
    let n = x.iter().zip(&y).filter(|(p, q)| p != q).count();
    (max, n as f64 / x.len() as f64)
}

#[test]
fn image_screenshot_equals_a_normal_run() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "n.png"]);
    view(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "2",
            "--screenshot",
            "v.png",
        ],
    );
    assert_same_image(&dir.path().join("v.png"), &dir.path().join("n.png"));
    // A batch: the arrow key goes to the next image.
    let p2 = dir.path().join("b");
    std::fs::create_dir(&p2).unwrap();
    photo(&p2, "1.png");
    let img = common::image_u8(64, 48, |x, y| [(x * 4) as u8, (y * 5) as u8, 255, 255]);
    fxgraph::io::save_image(&p2.join("2.png"), 64, 48, &img.pixels, &Default::default()).unwrap();
    normal(dir.path(), &["glow", "-i", "b/2.png", "-o", "n2.png"]);
    view(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "b/",
            "--view",
            "--view-frames",
            "2",
            "--view-do",
            "1:key Right",
            "--screenshot",
            "v2.png",
        ],
    );
    assert_same_image(&dir.path().join("v2.png"), &dir.path().join("n2.png"));
}

/// Five frames of a moving pattern, `f0000.png` ...
fn sequence(dir: &Path) {
    for i in 0..5u32 {
        let img = common::image_u8(48, 32, |x, y| {
            [
                ((x + 7 * i) * 5) as u8,
                (y * 7) as u8,
                ((x * y + i * 40) % 256) as u8,
                255,
            ]
        });
        let p = dir.join(format!("f{i:04}.png"));
        fxgraph::io::save_image(&p, 48, 32, &img.pixels, &Default::default()).unwrap();
    }
}

#[test]
fn sequence_frames_equal_the_normal_runs_frames_also_after_going_back() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    sequence(dir.path());
    for effect in ["frame_blend", "motion_trail"] {
        let out = format!("{effect}/%04d.png");
        normal(dir.path(), &[effect, "-i", "f%04d.png", "-o", &out]);
        let frame = |n: u32| dir.path().join(effect).join(format!("{n:04}.png"));
        // One frame further per frame shown: the 4th frame shown is frame 3.
        view(
            &d,
            dir.path(),
            &[
                effect,
                "-i",
                "f%04d.png",
                "--view",
                "--view-frames",
                "4",
                "--screenshot",
                "v3.png",
            ],
        );
        assert_same_image(&dir.path().join("v3.png"), &frame(3));
        // Pause at frame 3, go back twice: frame 1, with its history replayed
        // (frame_blend reads earlier frames, motion_trail its own earlier output).
        view(
            &d,
            dir.path(),
            &[
                effect,
                "-i",
                "f%04d.png",
                "--view",
                "--view-frames",
                "6",
                "--view-do",
                "4:key Space",
                "--view-do",
                "5:key Left",
                "--view-do",
                "6:key Left",
                "--screenshot",
                "v1.png",
            ],
        );
        assert_same_image(&dir.path().join("v1.png"), &frame(1));
    }
}

#[test]
fn scene_screenshot_equals_a_normal_run() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    let scene = ["--scene", "builtin:room", "--size", "160x120"];
    let mut args = vec!["tonemap"];
    args.extend(scene);
    let mut n = args.clone();
    n.extend(["-o", "n.png"]);
    normal(dir.path(), &n);
    let mut v = args.clone();
    v.extend(["--view", "--view-frames", "2", "--screenshot", "v.png"]);
    view(&d, dir.path(), &v);
    assert_same_image(&dir.path().join("v.png"), &dir.path().join("n.png"));
    // The G-buffer is in the pass list: AUX.depth is written as a run writes R32F.
    let mut a = args.clone();
    a.extend([
        "--view",
        "--view-frames",
        "2",
        "--view-do",
        "1:inspect aux:depth",
        "--screenshot",
        "depth.exr",
    ]);
    view(&d, dir.path(), &a);
    let (w, h, p) = pixels(&dir.path().join("depth.exr"));
    assert_eq!((w, h), (160, 120));
    let Pixels::F32(v) = p else {
        panic!("float depth")
    };
    assert!(
        v.chunks(4).all(|px| px[0] > 0.0 && px[0] == px[1]),
        "depth as grey, positive"
    );
}

#[test]
fn a_scene_without_size_follows_the_window_and_is_planned_again() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    // No --size: the render takes the image area; hiding the panel widens it.
    view(
        &d,
        dir.path(),
        &[
            "fxaa",
            "--scene",
            "builtin:room",
            "--view",
            "--view-frames",
            "3",
            "--view-do",
            "1:key Tab",
            "--screenshot",
            "wide.png",
        ],
    );
    let (w, h, _) = pixels(&dir.path().join("wide.png"));
    view(
        &d,
        dir.path(),
        &[
            "fxaa",
            "--scene",
            "builtin:room",
            "--view",
            "--view-frames",
            "2",
            "--screenshot",
            "narrow.png",
        ],
    );
    let (nw, nh, _) = pixels(&dir.path().join("narrow.png"));
    assert!(
        w > nw && h == nh,
        "the panel's width: {w}x{h} against {nw}x{nh}"
    );
    // Planned for the new size: the frame a run at that size writes.
    let size = format!("{w}x{h}");
    normal(
        dir.path(),
        &[
            "fxaa",
            "--scene",
            "builtin:room",
            "--size",
            &size,
            "-o",
            "n.png",
        ],
    );
    assert_same_image(&dir.path().join("wide.png"), &dir.path().join("n.png"));
}

#[test]
fn a_parameter_set_as_the_panel_does_changes_the_next_frame_as_set_would() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    // A pass parameter (set_param), an effect parameter feeding a uniform (applied
    // as set_param) and one that changes a #define (planned again).
    let cases: [(&str, &str, &str); 3] = [
        ("glow", "brightPass.threshold", "0.15"),
        ("tonemap", "tonemap.exposure", "1.5"),
        ("tonemap", "operator", "reinhard"),
    ];
    for (i, (effect, name, value)) in cases.iter().enumerate() {
        let set = format!("{name}={value}");
        let n = format!("n{i}.png");
        normal(
            dir.path(),
            &[effect, "-i", "in.png", "-o", &n, "--set", &set],
        );
        let v = format!("v{i}.png");
        let action = format!("1:set {set}");
        let o = view(
            &d,
            dir.path(),
            &[
                effect,
                "-i",
                "in.png",
                "--view",
                "--view-frames",
                "2",
                "--view-do",
                &action,
                "--view-do",
                "2:copy-set",
                "--screenshot",
                &v,
            ],
        );
        assert_same_image(&dir.path().join(&v), &dir.path().join(&n));
        // "Copy as --set" gives arguments that reproduce it.
        let line = stdout(&o);
        assert!(
            line.contains(&format!("--set {set}"))
                || line.contains(&format!("--set {effect}.{set}")),
            "copy-set printed {line:?}"
        );
        // Before the change the frame was the unchanged effect's.
        let u = format!("u{i}.png");
        normal(dir.path(), &[effect, "-i", "in.png", "-o", &u]);
        assert!(
            diff_u8(&dir.path().join(&u), &dir.path().join(&v)).0 > 0,
            "{set} changes the image"
        );
    }
    // An effect parameter in a loop bound (gaussian_blur's sigma): equal within one
    // 8-bit step (lavapipe specialises shaders on uniform values it sees in loop
    // bounds, so a value set after the first frame may round differently).
    normal(
        dir.path(),
        &[
            "gaussian_blur",
            "-i",
            "in.png",
            "-o",
            "g.png",
            "--set",
            "sigma=5",
        ],
    );
    view(
        &d,
        dir.path(),
        &[
            "gaussian_blur",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "2",
            "--view-do",
            "1:set sigma=5",
            "--screenshot",
            "gv.png",
        ],
    );
    let (max, share) = diff_u8(&dir.path().join("gv.png"), &dir.path().join("g.png"));
    assert!(
        max <= 1 && share < 0.01,
        "sigma=5: {max} steps, {:.3} % of samples",
        share * 100.0
    );
}

#[test]
fn the_inspected_pass_equals_a_run_of_the_effect_up_to_that_pass() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    std::fs::write(
        dir.path().join("upto.fx"),
        "EFFECT.upto = { PASS = {
            brightPass = SHADER.brightPass { img = IN }
            blurX = SHADER.blurX { img = PASS.brightPass  OUT.SCALE = (0.5, 0.5) }
        } OUT = blurX }",
    )
    .unwrap();
    normal(dir.path(), &["upto.fx", "-i", "in.png", "-o", "n.exr"]);
    view(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "2",
            "--view-do",
            "1:inspect blurX",
            "--screenshot",
            "v.exr",
        ],
    );
    assert_same_image(&dir.path().join("v.exr"), &dir.path().join("n.exr"));
    // Inspecting does not change the output: back to it, the same as a normal run.
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "o.png"]);
    view(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "3",
            "--view-do",
            "1:inspect blurY",
            "--view-do",
            "2:inspect output",
            "--screenshot",
            "vo.png",
        ],
    );
    assert_same_image(&dir.path().join("vo.png"), &dir.path().join("o.png"));
}

/// A one-pass effect whose shader scales its input by `k`, in `dir`.
fn scaling_effect(dir: &Path, k: &str) {
    std::fs::write(
        dir.join("k.fx"),
        "EFFECT.k = { PASS = { s = SHADER.scale { img = IN } } OUT = s }",
    )
    .unwrap();
    write_scale_shader(dir, &format!("c.rgb * {k}"));
}

fn write_scale_shader(dir: &Path, expr: &str) {
    let text = format!(
        "@group(0) @binding(0) var img: texture_2d<f32>;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {{
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    return vec4<f32>({expr}, c.a);
}}
"
    );
    // As an editor saves: a temporary renamed over the file.
    let tmp = dir.join("scale.wgsl.tmp~");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, dir.join("scale.wgsl")).unwrap();
}

/// A viewer running in the background: its stderr lines as they come, its stdin.
struct Running {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
    seen: String,
}

impl Running {
    fn start(d: &str, dir: &Path, args: &[&str]) -> Running {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fxrun"))
            .args(args)
            .current_dir(dir)
            .env("DISPLAY", d)
            .env_remove("WAYLAND_DISPLAY")
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let err = BufReader::new(child.stderr.take().unwrap());
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in err.lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Running {
            child,
            lines,
            seen: String::new(),
        }
    }

    /// The next stderr line containing `what` (panics if the viewer ends first).
    fn wait_for(&mut self, what: &str) -> String {
        loop {
            let line = self
                .lines
                .recv_timeout(Duration::from_secs(300))
                .unwrap_or_else(|_| panic!("no `{what}` from the viewer: {}", self.seen));
            self.seen.push_str(&line);
            self.seen.push('\n');
            if line.contains(what) {
                return line;
            }
        }
    }

    /// Answer a scripted `pause`.
    fn resume(&mut self) {
        let stdin = self.child.stdin.as_mut().unwrap();
        stdin.write_all(b"\n").unwrap();
        stdin.flush().unwrap();
    }

    /// Wait for the end: the exit status and all of stderr.
    fn finish(mut self) -> (i32, String) {
        drop(self.child.stdin.take());
        let status = self.child.wait().unwrap();
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(5)) {
            self.seen.push_str(&line);
            self.seen.push('\n');
        }
        (status.code().unwrap_or(-1), self.seen)
    }
}

/// Runs the viewer (waiting for a reload after frame 1), edits the shader once it
/// watches; returns its status and stderr.
fn view_with_edit(d: &str, dir: &Path, shot: &str, edit: &str) -> (i32, String) {
    let mut v = Running::start(
        d,
        dir,
        &[
            "k.fx",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "2",
            "--view-do",
            "1:wait-reload",
            "--screenshot",
            shot,
        ],
    );
    v.wait_for("watching");
    write_scale_shader(dir, edit);
    v.finish()
}

#[test]
fn a_reload_shows_the_edited_shader_and_a_broken_one_keeps_the_last_image() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    scaling_effect(dir.path(), "0.5");
    normal(dir.path(), &["k.fx", "-i", "in.png", "-o", "half.png"]);
    let (status, err) = view_with_edit(&d, dir.path(), "edited.png", "c.rgb * 0.25");
    assert_eq!(status, 0, "{err}");
    assert!(err.contains("reloaded"), "{err}");
    normal(dir.path(), &["k.fx", "-i", "in.png", "-o", "quarter.png"]);
    assert_same_image(
        &dir.path().join("edited.png"),
        &dir.path().join("quarter.png"),
    );
    // A broken shader: the error with its place, and the last good image stays.
    let (status, err) = view_with_edit(&d, dir.path(), "broken.png", "c.rgb * undefined_name");
    assert_eq!(status, 0, "{err}");
    assert!(
        err.contains("reload failed") && err.contains("scale.wgsl:4:"),
        "{err}"
    );
    assert!(err.contains("undefined_name"), "{err}");
    assert_same_image(
        &dir.path().join("broken.png"),
        &dir.path().join("quarter.png"),
    );
}

/// `x,y WxH` after `image at` in the pause line.
fn image_rect(line: &str) -> (u32, u32, u32, u32) {
    let rest = line.split("image at ").nth(1).expect("image at");
    let (pos, size) = rest.split_once(' ').unwrap();
    let (x, y) = pos.split_once(',').unwrap();
    let size = size.split_whitespace().next().unwrap();
    let (w, h) = size.split_once('x').unwrap();
    (
        x.parse().unwrap(),
        y.parse().unwrap(),
        w.parse().unwrap(),
        h.parse().unwrap(),
    )
}

#[test]
fn the_x_display_shows_the_output_in_the_window() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    normal(dir.path(), &["glow", "-i", "in.png", "-o", "n.png"]);
    // Panel hidden, 1:1 pixels, paused after frame 2.
    let mut v = Running::start(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "3",
            "--view-do",
            "1:key Tab",
            "--view-do",
            "1:key 1",
            "--view-do",
            "2:pause",
        ],
    );
    let line = v.wait_for("paused at frame");
    let (x, y, w, h) = image_rect(&line);
    assert_eq!((w, h), (96, 64), "{line}");
    // The frame is presented before the pause; lavapipe's X11 WSI may put it on the
    // screen a moment later, so look a few times.
    let (_, _, Pixels::U8(want)) = pixels(&dir.path().join("n.png")) else {
        panic!()
    };
    let t0 = Instant::now();
    let psnr = loop {
        let (sw, _, screen) = grab_screen(&d, dir.path());
        let mut got = Vec::new();
        let mut exp = Vec::new();
        for row in 0..h {
            for col in 0..w {
                let s = (((y + row) * sw + x + col) * 3) as usize;
                let t = ((row * w + col) * 4) as usize;
                got.extend(screen[s..s + 3].iter().map(|&v| v as f32 / 255.0));
                exp.extend(want[t..t + 3].iter().map(|&v| v as f32 / 255.0));
            }
        }
        let p = common::psnr(&got, &exp, 1.0);
        if p >= 50.0 || t0.elapsed() > Duration::from_secs(10) {
            break p;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    v.resume();
    let (status, err) = v.finish();
    assert_eq!(status, 0, "{err}");
    assert!(psnr >= 50.0, "the screen shows the output at {psnr:.1} dB");
}

#[test]
fn errors_are_refused_at_the_start_and_shown_in_the_window_after_a_reload() {
    let Some((d, _gpu)) = setup() else { return };
    let dir = tempdir();
    photo(dir.path(), "in.png");
    std::fs::write(
        dir.path().join("bad.fx"),
        "EFFECT.bad = { PASS = { s = SHADER.nosuchshader { img = IN } } OUT = s }",
    )
    .unwrap();
    // An effect that does not compile at the start is an input error (exit 1).
    let o = fxrun_view(
        &d,
        dir.path(),
        &["bad.fx", "-i", "in.png", "--view", "--view-frames", "1"],
    );
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.fx:1:"), "{}", stderr(&o));
    // A scripted set out of range is refused, naming the range.
    let o = fxrun_view(
        &d,
        dir.path(),
        &[
            "glow",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "1",
            "--view-do",
            "1:set brightPass.threshold=-3",
        ],
    );
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("out of range"), "{}", stderr(&o));
    // After a broken reload the window's title says so (the panel shows the error).
    scaling_effect(dir.path(), "0.5");
    let mut v = Running::start(
        &d,
        dir.path(),
        &[
            "k.fx",
            "-i",
            "in.png",
            "--view",
            "--view-frames",
            "2",
            "--view-do",
            "1:wait-reload",
            "--view-do",
            "2:pause",
        ],
    );
    v.wait_for("watching");
    write_scale_shader(dir.path(), "c.rgb * undefined_name");
    v.wait_for("paused at frame");
    let names = window_names(&d);
    v.resume();
    let (status, err) = v.finish();
    assert_eq!(status, 0, "{err}");
    assert!(names.contains("error (see the panel)"), "{names}");
}

#[test]
fn without_a_display_the_viewer_is_refused_with_exit_1() {
    let dir = tempdir();
    photo(dir.path(), "in.png");
    let run = |display: Option<&str>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_fxrun"));
        c.args(["glow", "-i", "in.png", "--view"])
            .current_dir(dir.path())
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("WAYLAND_SOCKET")
            .env("XDG_RUNTIME_DIR", std::env::temp_dir());
        match display {
            Some(d) => c.env("DISPLAY", d),
            None => c.env_remove("DISPLAY"),
        };
        c.output().unwrap()
    };
    let o = run(None);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("--view needs a display"),
        "{}",
        stderr(&o)
    );
    // A display that no server answers: the same, never a panic.
    let o = run(Some(":239"));
    assert_eq!(code(&o), 1);
    let e = stderr(&o);
    assert!(
        e.contains("cannot open the display (DISPLAY=:239)")
            && !e.contains("panicked")
            && !e.contains(".rs:"),
        "{e}"
    );
    // The viewer's options alone are refused.
    let o = common::cli::fxrun_in(
        dir.path(),
        &["glow", "-i", "in.png", "-o", "x.png", "--view-frames", "2"],
    );
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("options of --view"));
}
