//! Helpers of the viewer tests (`tests/viewer.rs`, `tests/viewer_live.rs`): the
//! display and the engine, test images, normal and viewer runs, a viewer running in
//! the background (its stderr lines, a scripted `pause`), image comparisons, and
//! the screen.
#![allow(dead_code)]

use super::cli::{code, stderr};
use super::display::{display, fxrun_view, grab_screen, viewer_command};
use fxgraph::io::{load_image, LoadOptions, Pixels};
use std::ffi::OsStr;
use std::fmt::Debug;
use std::io::{BufRead as _, BufReader, Write as _};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// A display and an adapter, or `None` (skipped). The engine's lock is held while
/// the test runs, so the viewers of the tests run one at a time.
pub fn setup() -> Option<(
    String,
    std::sync::MutexGuard<'static, fxgraph::gpu::executor::Engine>,
)> {
    let d = display()?;
    let gpu = super::engine()?;
    Some((d, gpu))
}

/// [`setup`] and a folder holding the test [`photo`] `in.png`: the display, the
/// engine's lock and the folder, or `None` (skipped).
pub fn setup_with_photo() -> Option<(
    String,
    std::sync::MutexGuard<'static, fxgraph::gpu::executor::Engine>,
    tempfile::TempDir,
)> {
    let (d, gpu) = setup()?;
    let dir = tempdir();
    photo(dir.path(), "in.png");
    Some((d, gpu, dir))
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// A 96x64 test photo with bright spots (so glow has something to do).
pub fn photo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let img = super::pattern_u8(96, 64);
    fxgraph::io::save_image(&path, 96, 64, &img.pixels, &Default::default()).unwrap();
    path
}

/// `fxrun ARGS` (a normal run) in `dir`, which must succeed.
pub fn normal(dir: &Path, args: &[&str]) {
    let o = super::cli::fxrun_in(dir, args);
    assert_eq!(code(&o), 0, "fxrun {args:?}: {}", stderr(&o));
}

/// The arguments of a scripted viewer run: `ARGS --view --view-frames FRAMES`,
/// a `--view-do ACTION` for each of `actions` (`N:WHAT`: after frame N), and
/// `--screenshot SHOT` when a screenshot is named.
pub fn scripted(args: &[&str], frames: u32, actions: &[&str], shot: Option<&str>) -> Vec<String> {
    let mut v: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    v.extend(["--view".into(), "--view-frames".into(), frames.to_string()]);
    for action in actions {
        v.extend(["--view-do".into(), action.to_string()]);
    }
    if let Some(shot) = shot {
        v.extend(["--screenshot".into(), shot.into()]);
    }
    v
}

/// `fxrun ARGS --view ...` in `dir` on the display, which must succeed.
pub fn view<S: AsRef<OsStr> + Debug>(d: &str, dir: &Path, args: &[S]) -> std::process::Output {
    let o = fxrun_view(d, dir, args);
    assert_eq!(code(&o), 0, "fxrun {args:?}: {}", stderr(&o));
    o
}

/// [`view`] of the run [`scripted`] with `args`, `frames` and `actions` that
/// ends with the screenshot `shot`.
pub fn view_shot(d: &str, dir: &Path, args: &[&str], frames: u32, actions: &[&str], shot: &str) {
    view(d, dir, &scripted(args, frames, actions, Some(shot)));
}

pub fn pixels(path: &Path) -> (u32, u32, Pixels) {
    let img = load_image(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    (img.width, img.height, img.pixels)
}

/// The two files hold the same image, sample for sample.
pub fn assert_same_image(a: &Path, b: &Path) {
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
pub fn diff_u8(a: &Path, b: &Path) -> (u8, f64) {
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

/// A one-pass effect whose shader scales its input by `k`, in `dir`.
pub fn scaling_effect(dir: &Path, k: &str) {
    std::fs::write(
        dir.join("k.fx"),
        "EFFECT.k = { PASS = { s = SHADER.scale { img = IN } } OUT = s }",
    )
    .unwrap();
    write_scale_shader(dir, &format!("c.rgb * {k}"));
}

pub fn write_scale_shader(dir: &Path, expr: &str) {
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
pub struct Running {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
    seen: String,
}

impl Running {
    pub fn start<S: AsRef<OsStr>>(d: &str, dir: &Path, args: &[S]) -> Running {
        let mut child = viewer_command(d, dir, args)
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
    pub fn wait_for(&mut self, what: &str) -> String {
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
    pub fn resume(&mut self) {
        let stdin = self.child.stdin.as_mut().unwrap();
        stdin.write_all(b"\n").unwrap();
        stdin.flush().unwrap();
    }

    /// Wait for the end: the exit status and all of stderr.
    pub fn finish(mut self) -> (i32, String) {
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
pub fn view_with_edit(d: &str, dir: &Path, shot: &str, edit: &str) -> (i32, String) {
    let args = ["k.fx", "-i", "in.png"];
    let mut v = Running::start(d, dir, &scripted(&args, 2, &["1:wait-reload"], Some(shot)));
    v.wait_for("watching");
    write_scale_shader(dir, edit);
    v.finish()
}

/// `x,y WxH` after `image at` in the pause line.
pub fn image_rect(line: &str) -> (u32, u32, u32, u32) {
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

/// PSNR of a region of a screenshot against `expected(col, row)` (RGB, 0..1).
pub fn region_psnr(
    (sw, _, screen): &(u32, u32, Vec<u8>),
    (x, y, w, h): (u32, u32, u32, u32),
    expected: impl Fn(u32, u32) -> [f32; 3],
) -> f64 {
    let (mut got, mut exp) = (Vec::new(), Vec::new());
    for row in 0..h {
        for col in 0..w {
            let s = (((y + row) * sw + x + col) * 3) as usize;
            got.extend(screen[s..s + 3].iter().map(|&v| v as f32 / 255.0));
            exp.extend(expected(col, row));
        }
    }
    super::psnr(&got, &exp, 1.0)
}

/// [`region_psnr`] of the display: the frame is presented before the viewer
/// pauses, but lavapipe's X11 WSI may put it on the screen a moment later, so the
/// screen is looked at again (for up to 10 s) while it does not match.
pub fn screen_psnr(
    d: &str,
    dir: &Path,
    region: (u32, u32, u32, u32),
    expected: impl Fn(u32, u32) -> [f32; 3],
) -> f64 {
    let t0 = Instant::now();
    loop {
        let p = region_psnr(&grab_screen(d, dir), region, &expected);
        if p >= 50.0 || t0.elapsed() > Duration::from_secs(10) {
            return p;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}
