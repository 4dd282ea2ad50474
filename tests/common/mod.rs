//! Shared helpers of the GPU tests: one engine per test binary, CPU images, metrics.
#![allow(dead_code)]

pub mod anim_gltf;
pub mod bench;
pub mod brdf;
pub mod cli;
pub mod compile;
pub mod display;
pub mod gltf_gen;
pub mod ibl;
pub mod layers;
pub mod mips;
pub mod raster;
pub mod render_bench;
pub mod renders;
pub mod rng;
pub mod samples;
pub mod scenes;
pub mod shadow_scene;
pub mod skinned_scene;
pub mod slang;
pub mod stream;
pub mod tools;
pub mod variant_bench;
pub mod video;
pub mod viewer;

use fxgraph::app::{apply_in_memory, RunError};
use fxgraph::gpu::context::{require_gpu, AdapterChoice, GpuContext};
use fxgraph::gpu::executor::Engine;
use fxgraph::io::{FileFormat, Image, Pixels, SourceInfo};
use fxgraph::script::types::Format;
use std::sync::{Mutex, OnceLock};

/// `glow` up to its `blurX` pass (`effects/glow.fx` cut short): what an inspected
/// `blurX` of `glow` holds.
pub const UPTO_BLUR_X: &str = "EFFECT.upto = { PASS = {
    brightPass = SHADER.brightPass { img = IN }
    blurX = SHADER.blurX { img = PASS.brightPass  OUT.SCALE = (0.5, 0.5) }
} OUT = blurX }";

/// The test engine, or `None` (test skipped) when there is no adapter and
/// FX_REQUIRE_GPU is not set. With FX_REQUIRE_GPU=1 a missing adapter panics.
pub fn engine() -> Option<std::sync::MutexGuard<'static, Engine>> {
    static ENGINE: OnceLock<Option<Mutex<Engine>>> = OnceLock::new();
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let e = ENGINE.get_or_init(|| match GpuContext::new(&AdapterChoice::Auto) {
        Ok(ctx) => Some(Mutex::new(Engine::new(ctx))),
        Err(e) => {
            if require_gpu() {
                panic!("FX_REQUIRE_GPU=1 but no GPU adapter: {e}");
            }
            eprintln!("skipping GPU test: no adapter ({e})");
            None
        }
    });
    e.as_ref()
        .map(|m| m.lock().unwrap_or_else(|p| p.into_inner()))
}

/// Runs `f` on `eng` set to `execution`, then sets it back (also where `f`
/// panics): for the passes whose `@compute` entry point runs under compute
/// execution only (`// @execution(compute)`, docs/shaders.md).
pub fn with_execution<R>(
    eng: &mut Engine,
    execution: fxgraph::gpu::executor::Execution,
    f: impl FnOnce(&mut Engine) -> R,
) -> R {
    struct Back<'a>(&'a mut Engine, fxgraph::gpu::executor::Execution);
    impl Drop for Back<'_> {
        fn drop(&mut self) {
            self.0.set_execution(self.1);
        }
    }
    let before = eng.execution();
    eng.set_execution(execution);
    let back = Back(eng, before);
    f(&mut *back.0)
}

/// The test engine's GPU context (held locked, like [`engine`]), or `None` (test
/// skipped): for the renderer tests, which need the device and not the engine.
pub fn gpu_context() -> Option<Gpu> {
    engine().map(Gpu)
}

/// The GPU context of the locked test engine.
pub struct Gpu(std::sync::MutexGuard<'static, Engine>);

impl std::ops::Deref for Gpu {
    type Target = GpuContext;
    fn deref(&self) -> &GpuContext {
        &self.0.ctx
    }
}

/// A scratch folder for a test that needs the GPU, or `None` (test skipped) when
/// [`engine`] has no adapter.
pub fn gpu_scratch() -> Option<tempfile::TempDir> {
    engine().map(|_| tempfile::tempdir().unwrap())
}

/// The RGBA samples of a `w` x `h` image from a closure of (x, y), row by row.
fn samples<T: Copy>(w: u32, h: u32, f: impl Fn(u32, u32) -> [T; 4]) -> Vec<T> {
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            v.extend_from_slice(&f(x, y));
        }
    }
    v
}

/// A `w` x `h` RGBA image of `pixels` as read from a file of `format` with
/// `bit_depth` bits per sample.
fn image(w: u32, h: u32, pixels: Pixels, format: FileFormat, bit_depth: u8) -> Image {
    let source = SourceInfo {
        format,
        bit_depth,
        has_alpha: true,
        float: matches!(pixels, Pixels::F32(_)),
    };
    Image {
        width: w,
        height: h,
        pixels,
        source,
    }
}

/// An 8-bit RGBA image from a closure of (x, y) -> [r, g, b, a].
pub fn image_u8(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Image {
    image(w, h, Pixels::U8(samples(w, h, f)), FileFormat::Png, 8)
}

/// A linear float RGBA image from a closure.
pub fn image_f32(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
    image(w, h, Pixels::F32(samples(w, h, f)), FileFormat::Exr, 32)
}

/// A deterministic test pattern with edges, gradients and colour (8-bit).
pub fn pattern_u8(w: u32, h: u32) -> Image {
    image_u8(w, h, |x, y| {
        let checker = ((x / 7 + y / 5) % 2) as u8;
        let r = ((x * 255) / w.max(1)) as u8;
        let g = ((y * 255) / h.max(1)) as u8;
        let b = if checker == 1 { 220 } else { 30 };
        let spot = if (x as i32 - w as i32 / 2).pow(2) + (y as i32 - h as i32 / 2).pow(2)
            < (w.min(h) as i32 / 6).pow(2)
        {
            255
        } else {
            0
        };
        [r.max(spot), g, b, 255]
    })
}

/// The words of `line` (split at spaces): `--set` arguments written as one line,
/// `"amount=1 sigma=2"`.
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// What [`run`] returns: the output's width, height and pixels.
pub type Ran = Result<(u32, u32, Pixels), RunError>;

/// Run the effects `fx` with `sets` (`NAME=VALUE`) on `img`; output read back in `out`.
pub fn run(eng: &mut Engine, fx: &[&str], sets: &[&str], img: &Image, out: Format) -> Ran {
    run_with(eng, fx, sets, img, out, false)
}

/// Like [`run`] with `--assume-linear` (8-bit values are used as they are).
pub fn run_raw(eng: &mut Engine, fx: &[&str], sets: &[&str], img: &Image, out: Format) -> Ran {
    run_with(eng, fx, sets, img, out, true)
}

fn run_with(
    eng: &mut Engine,
    fx: &[&str],
    sets: &[&str],
    img: &Image,
    out: Format,
    raw: bool,
) -> Ran {
    let e: Vec<String> = fx.iter().map(|s| s.to_string()).collect();
    let o: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    apply_in_memory(eng, &e, &o, img, &[], out, raw)
}

/// Runs the effect `name` with `sets` (`NAME=VALUE`) on `img`, output read back in
/// `out`: its pixels (panics, naming the effect, on an error).
pub fn apply_fx(
    engine: &mut Engine,
    name: &str,
    sets: &[&str],
    img: &Image,
    out: Format,
) -> Pixels {
    run(engine, &[name], sets, img, out)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .2
}

/// Largest absolute difference between two sample arrays.
pub fn max_abs_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len(), "sample counts differ");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// PSNR in dB of `a` against `b`, samples in [0, peak].
pub fn psnr(a: &[f32], b: &[f32], peak: f32) -> f64 {
    assert_eq!(a.len(), b.len());
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| ((x - y) as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * ((peak as f64).powi(2) / mse).log10()
    }
}

pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.max(0.0);
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Pixels as linear floats (U8 sRGB-decoded, alpha / 255).
pub fn linear(p: &Pixels) -> Vec<f32> {
    match p {
        Pixels::F32(v) => v.clone(),
        Pixels::U8(v) => v
            .iter()
            .enumerate()
            .map(|(i, &b)| {
                if i % 4 == 3 {
                    b as f32 / 255.0
                } else {
                    srgb_to_linear(b as f32 / 255.0)
                }
            })
            .collect(),
    }
}

/// Sample at (x, y, channel) of an RGBA buffer.
pub fn at(v: &[f32], w: u32, x: u32, y: u32, c: usize) -> f32 {
    v[((y * w + x) * 4) as usize + c]
}

/// Write `pixels` next to the test outputs for review (tests/output/NAME.png).
pub fn save_for_review(name: &str, w: u32, h: u32, p: &Pixels) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/output");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.png"));
    fxgraph::io::save_image(&path, w, h, p, &Default::default()).unwrap();
    path
}

/// Compare against a committed reference PNG (tests/reference/NAME.png) with a PSNR
/// floor. A missing reference fails and writes the actual image for review
/// (tests/output/NAME.png); it is never created silently.
pub fn check_reference(name: &str, w: u32, h: u32, p: &Pixels, min_psnr: f64) {
    let reference = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("tests/reference/{name}.png"));
    let actual = save_for_review(name, w, h, p);
    let Ok(img) = fxgraph::io::load_image(&reference, &Default::default()) else {
        panic!(
            "missing reference {}; the actual image is at {} — review it and copy it there to accept",
            reference.display(),
            actual.display()
        );
    };
    assert_eq!((img.width, img.height), (w, h), "reference size differs");
    let a = linear(p);
    let b = linear(&img.pixels);
    let q = psnr(&a, &b, 1.0);
    assert!(
        q >= min_psnr,
        "{name}: PSNR {q:.2} dB against the reference < {min_psnr} dB (actual image: {})",
        actual.display()
    );
}

/// The harness name of test `name` of the module `module` (`module_path!()`):
/// the path without the binary's name (tests/engine and tests/scene gather
/// files as modules), for a test that runs itself in a child process.
pub fn test_name(module: &str, name: &str) -> String {
    match module.split_once("::") {
        Some((_, m)) => format!("{m}::{name}"),
        None => name.to_string(),
    }
}
