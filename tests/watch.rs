//! `fxrun --watch`: a changed shader re-runs the effect; a broken one is reported and
//! the watch goes on; options it does not take are refused.

use crate::common;

use std::io::Read as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const FX: &str = "EFFECT.solid = { PASS = { m = SHADER.solid { a = IN } } OUT = m }";

fn shader(rgb: &str) -> String {
    format!(
        "@group(0) @binding(0) var a: texture_2d<f32>;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {{
    return vec4<f32>({rgb}, 1.0) + 0.0 * textureLoad(a, vec2<i32>(pos.xy), 0);
}}
"
    )
}

/// Polls `cond` every 50 ms until it holds; panics with `what` after `secs`.
fn wait_until(secs: u64, what: &str, mut cond: impl FnMut() -> bool) {
    let t0 = Instant::now();
    while !cond() {
        assert!(
            t0.elapsed() < Duration::from_secs(secs),
            "timed out: {what}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Replaces a file as an editor does: write a temporary, rename it over.
fn save(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp~");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// `fxrun D/solid.fx -i INPUT -o OUTPUT --watch` (with `solid.fx` and a red
/// `solid.wgsl` written in D), its stderr collected as it comes; killed on drop.
struct Watch {
    child: std::process::Child,
    err: Arc<Mutex<String>>,
}

impl Watch {
    fn start(d: &Path, input: &Path, output: &Path) -> Watch {
        std::fs::write(d.join("solid.fx"), FX).unwrap();
        std::fs::write(d.join("solid.wgsl"), shader("1.0, 0.0, 0.0")).unwrap();
        Watch::start_effect(&d.join("solid.fx"), input, output)
    }

    /// `fxrun EFFECT -i INPUT -o OUTPUT --watch`.
    fn start_effect(effect: &Path, input: &Path, output: &Path) -> Watch {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fxrun"))
            .arg(effect)
            .arg("-i")
            .arg(input)
            .arg("-o")
            .arg(output)
            .arg("--watch")
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .stderr(Stdio::piped())
            .stdout(Stdio::null())
            .spawn()
            .unwrap();
        let err = Arc::new(Mutex::new(String::new()));
        let sink = err.clone();
        let mut pipe = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = pipe.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        let w = Watch { child, err };
        wait_until(120, "the first run", || w.watching() >= 1);
        w
    }

    fn stderr(&self) -> String {
        self.err.lock().unwrap().clone()
    }

    /// How many times it has said it is watching (once after each run).
    fn watching(&self) -> usize {
        self.stderr().matches("watching").count()
    }

    fn still_running(&mut self) -> bool {
        self.child.try_wait().unwrap().is_none()
    }
}

impl Drop for Watch {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn save_png(path: &Path, w: u32, h: u32) {
    let img = common::pattern_u8(w, h);
    // A hidden temporary of the same format, renamed over (as a copy tool does).
    let tmp = path.with_file_name(".partial.png");
    fxgraph::io::save_image(
        &tmp,
        img.width,
        img.height,
        &img.pixels,
        &Default::default(),
    )
    .unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// A 16x8 `in.png` in `d`, and the `out.png` beside it to write.
fn image_job(d: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let input = d.join("in.png");
    save_png(&input, 16, 8);
    (input, d.join("out.png"))
}

/// `-i DIR -o DIR --watch`: an image that appears in the input folder is processed
/// alone (the others are not written again); a changed shader re-runs them all.
#[test]
fn a_watched_input_folder_processes_new_images() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path();
    let (input, output) = (d.join("in"), d.join("out"));
    std::fs::create_dir(&input).unwrap();
    save_png(&input.join("a.png"), 16, 8);
    let mut w = Watch::start(d, &input, &output);
    let stderr = || w.stderr();
    let watching = || w.watching();
    assert!(stderr().contains("1 input folder"), "{}", stderr());
    let a_time = || {
        std::fs::metadata(output.join("a.png"))
            .unwrap()
            .modified()
            .unwrap()
    };
    let first_a = a_time();
    // A new image of another size: processed on its own.
    save_png(&input.join("b.png"), 24, 10);
    wait_until(60, "b.png processed", || {
        output.join("b.png").exists() && watching() >= 2
    });
    assert!(
        stderr().contains("1 new or changed input(s)"),
        "{}",
        stderr()
    );
    assert_eq!(a_time(), first_a, "a.png was written again: {}", stderr());
    let b = fxgraph::io::load_image(&output.join("b.png"), &Default::default()).unwrap();
    assert_eq!((b.width, b.height), (24, 10));
    // The effect changes: every image again.
    save(&d.join("solid.wgsl"), &shader("0.0, 0.0, 1.0"));
    wait_until(60, "the re-run after the shader changed", || {
        a_time() != first_a && watching() >= 3
    });
    assert!(w.still_running(), "{}", w.stderr());
}

#[test]
fn a_changed_shader_reruns_and_a_broken_one_keeps_watching() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path();
    let (input, out) = image_job(d);
    let mut w = Watch::start(d, &input, &out);
    let stderr = || w.stderr();
    let watching = || w.watching();
    let first = std::fs::read(&out).expect("the first output");
    // A new colour: the output is written again, with other pixels.
    save(&d.join("solid.wgsl"), &shader("0.0, 0.0, 1.0"));
    wait_until(60, "the re-run after the shader changed", || {
        std::fs::read(&out).is_ok_and(|b| b != first)
    });
    let blue = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    let red = {
        std::fs::write(d.join("red.png"), &first).unwrap();
        fxgraph::io::load_image(&d.join("red.png"), &Default::default()).unwrap()
    };
    assert_ne!(format!("{:?}", blue.pixels), format!("{:?}", red.pixels));
    // A broken shader: the diagnostic is printed and the process keeps watching.
    wait_until(60, "watching again", || watching() >= 2);
    save(&d.join("solid.wgsl"), "@fragment fn fs_main( -> oops\n");
    wait_until(60, "the diagnostic of the broken shader", || {
        stderr().contains("solid.wgsl") && stderr().contains("error")
    });
    wait_until(60, "watching after the error", || watching() >= 3);
    assert!(
        w.still_running(),
        "the watch ended on a shader error: {}",
        w.stderr()
    );
}

/// A one-pass slang preset whose shader writes `rgb` (GLSL), as its path.
fn slang_solid(d: &Path, rgb: &str) -> std::path::PathBuf {
    let shader = common::slang::one_pass_shader(
        "",
        &format!("FragColor = vec4({rgb}, 1.0) + 0.0 * texture(Source, vTexCoord);"),
        "",
    );
    save(&d.join("solid.slang"), &shader);
    let preset = d.join("solid.slangp");
    std::fs::write(&preset, "shaders = 1\nshader0 = solid.slang\n").unwrap();
    preset
}

/// A slang preset under `--watch`: editing its `.slang` shader lowers the preset
/// again and re-runs it.
#[cfg(feature = "slang")]
#[test]
fn a_changed_slang_shader_is_lowered_again() {
    let Some(dir) = common::gpu_scratch() else {
        return;
    };
    let d = dir.path();
    let (input, out) = image_job(d);
    let preset = slang_solid(d, "1.0, 0.0, 0.0");
    let mut w = Watch::start_effect(&preset, &input, &out);
    let first = std::fs::read(&out).expect("the first output");
    slang_solid(d, "0.0, 0.0, 1.0");
    wait_until(60, "the re-run after the slang shader changed", || {
        std::fs::read(&out).is_ok_and(|b| b != first)
    });
    let blue = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    let fxgraph::io::Pixels::U8(px) = &blue.pixels else {
        panic!("an 8-bit output")
    };
    assert_eq!(&px[..4], &[0, 0, 255, 255], "{}", w.stderr());
    assert!(w.still_running(), "{}", w.stderr());
}

#[test]
fn watch_refuses_analysis_modes_and_streams_with_exit_1() {
    for args in [
        &["glow", "--check", "--watch"][..],
        &["glow", "-i", "-", "-o", "-", "--watch"][..],
        &["--scene", "builtin:room", "-o", "x.png", "--watch"][..],
        // The output folder as an input folder: every output would be a new input.
        &["glow", "-i", "src", "-o", "src", "--watch"][..],
    ] {
        let o = common::cli::fxrun(args);
        let err = common::cli::stderr(&o);
        assert_eq!(common::cli::code(&o), 1, "{args:?}: {err}");
        assert!(err.contains("--watch"), "{args:?}: {err}");
    }
}
