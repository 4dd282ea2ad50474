//! An X display for the viewer tests (`fxrun --view`): `DISPLAY` when it is set,
//! otherwise an Xvfb started on a free display number for this test binary and
//! stopped when the binary exits (a watcher shell kills it once the test process
//! is gone). Without either, a test is skipped, or fails under FX_REQUIRE_GPU=1
//! (CI), as the GPU tests do.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The `DISPLAY` value for the viewer, or `None` (skip) without one.
pub fn display() -> Option<String> {
    static DISPLAY: OnceLock<Option<String>> = OnceLock::new();
    DISPLAY
        .get_or_init(|| {
            if let Some(d) = std::env::var("DISPLAY").ok().filter(|d| !d.is_empty()) {
                return Some(d);
            }
            match start_xvfb() {
                Ok(d) => Some(d),
                Err(e) => {
                    if fxgraph::gpu::context::require_gpu() {
                        panic!("FX_REQUIRE_GPU=1 but no X display for the viewer tests: {e}");
                    }
                    eprintln!("skipping viewer test: no X display ({e})");
                    None
                }
            }
        })
        .clone()
}

/// Start `Xvfb :N` on the first free N from 90, and a shell that stops it when this
/// process ends.
fn start_xvfb() -> Result<String, String> {
    for n in 90..140u32 {
        let lock = format!("/tmp/.X{n}-lock");
        let socket = format!("/tmp/.X11-unix/X{n}");
        if Path::new(&lock).exists() || Path::new(&socket).exists() {
            continue;
        }
        let me = std::process::id();
        let script = format!(
            "Xvfb :{n} -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 & x=$!; \
             while kill -0 {me} 2>/dev/null && kill -0 $x 2>/dev/null; do sleep 1; done; kill $x 2>/dev/null"
        );
        Command::new("sh")
            .args(["-c", &script])
            .stdin(Stdio::null())
            .spawn()
            .map_err(|e| format!("cannot run sh: {e}"))?;
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(20) {
            if Path::new(&socket).exists() {
                return Ok(format!(":{n}"));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        return Err(format!(
            "Xvfb :{n} did not start (is Xvfb installed? Debian: apt-get install xvfb)"
        ));
    }
    Err("no free X display number in :90..:139".into())
}

/// The `fxrun ARGS` command in `dir` on the test display (no Wayland), not started.
pub fn viewer_command<S: AsRef<OsStr>>(display: &str, dir: &Path, args: &[S]) -> Command {
    let mut c = super::cli::command(args);
    c.current_dir(dir)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY");
    c
}

/// `fxrun ARGS` in `dir` on the test display.
pub fn fxrun_view<S: AsRef<OsStr>>(display: &str, dir: &Path, args: &[S]) -> Output {
    viewer_command(display, dir, args)
        .stdin(Stdio::null())
        .output()
        .expect("run fxrun")
}

/// A screenshot of the whole display (ImageMagick's `import -window root`) as
/// 8-bit RGB rows: (width, height, bytes).
pub fn grab_screen(display: &str, dir: &Path) -> (u32, u32, Vec<u8>) {
    let path = dir.join("screen.png");
    let mut import = Command::new("import");
    import
        .args(["-window", "root"])
        .arg(&path)
        .env("DISPLAY", display);
    let install = "run ImageMagick's import (Debian: apt-get install imagemagick)";
    super::tools::checked(&mut import, "import -window root", install);
    let img = fxgraph::io::load_image(&path, &Default::default()).expect("decode the screenshot");
    let fxgraph::io::Pixels::U8(rgba) = img.pixels else {
        panic!("an 8-bit screenshot expected");
    };
    let rgb = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    (img.width, img.height, rgb)
}

/// The names of the top-level windows on the display (`xwininfo -root -tree`).
pub fn window_names(display: &str) -> String {
    let out = Command::new("xwininfo")
        .args(["-root", "-tree"])
        .env("DISPLAY", display)
        .output()
        .expect("run xwininfo (Debian: apt-get install x11-utils)");
    String::from_utf8_lossy(&out.stdout).into_owned()
}
