//! The compute-native temporal and tile passes (docs/architecture.md,
//! "Execution paths") give what their `@fragment` entry points give:
//!
//! - pass by pass, on the same inputs under compute execution: each pass runs
//!   once at its storage format (its `@compute` entry point) and once at
//!   another (its `@fragment` one is drawn), and the values agree exactly
//!   (motion_blur's tile and neighbour maxima: comparisons only;
//!   temporal_denoise's block matching and refinement: the same costs summed in
//!   the same order, the same scans; its noise estimate: integer counts, the
//!   same bisection);
//! - effect by effect, over frames with motion and history (taa, motion_blur on
//!   a rendered scene with an orbiting camera), fragment against compute
//!   execution, where the timings show which entry point each pass ran.
//!
//! The reference is the fragment entry point, which the effects' own oracle
//! tests check (tests/effects/motion_blur.rs, tests/effects/taa.rs,
//! tests/effects/temporal_denoise.rs, tests/taa_scene.rs).

use crate::common;

use common::cli::{command, save};
use fxgraph::gpu::context::{require_gpu, AdapterChoice, GpuContext};
use fxgraph::io::{load_image, LoadOptions, Pixels};
use serde_json::Value;
use std::path::Path;

/// Whether a GPU is present (tests skip without one unless FX_REQUIRE_GPU=1).
fn gpu() -> bool {
    match GpuContext::new(&AdapterChoice::Auto) {
        Ok(_) => true,
        Err(e) => {
            assert!(!require_gpu(), "FX_REQUIRE_GPU=1 but no adapter: {e}");
            false
        }
    }
}

/// A 96x64 frame `t` of a textured picture moving by (2t, t) pixels, with a
/// fixed pseudo-random grain (block matching has near-ties to decide) and flat
/// areas (tile maxima have equal lengths to decide).
fn frame(t: u32) -> fxgraph::io::Image {
    let (w, h) = (96u32, 64u32);
    let mut px = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let (xs, ys) = (x as f32 + 2.0 * t as f32, y as f32 + t as f32);
            let grain = ((x * 7919 + y * 104_729) % 97) as f32 / 97.0 - 0.5;
            let flat = xs > 60.0 && xs < 80.0;
            let tex = if flat {
                0.25
            } else {
                0.5 + 0.3 * (xs * 0.45).sin() * (ys * 0.3).cos() + 0.05 * grain
            };
            px.extend([tex, 0.8 * tex + 0.1, 1.0 - tex, 1.0]);
        }
    }
    common::samples::float_image(w, h, px)
}

/// The output images (float, rgba) and every (pass, execution) of a run of
/// `args` under `execution`.
fn run(
    dir: &Path,
    args: &[&str],
    outputs: &[String],
    execution: &str,
) -> (Vec<Vec<f32>>, Vec<(String, String)>) {
    let json = dir.join("timings.json");
    let mut all: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    all.extend(["--execution", execution, "--timings-json"].map(String::from));
    all.push(json.display().to_string());
    let o = command(&all).current_dir(dir).output().expect("run fxrun");
    assert!(
        o.status.success(),
        "{args:?} ({execution}): {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let images = outputs
        .iter()
        .map(|name| {
            let img = load_image(&dir.join(name), &LoadOptions::default()).unwrap();
            match img.pixels {
                Pixels::F32(v) => v,
                Pixels::U8(v) => v.iter().map(|&b| f32::from(b) / 255.0).collect(),
            }
        })
        .collect();
    let report: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let mut executions = Vec::new();
    collect_executions(&report, &mut executions);
    (images, executions)
}

/// Every (pass path, execution) pair of a timings report.
fn collect_executions(v: &Value, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(m) => {
            if let (Some(Value::String(e)), Some(Value::String(p))) =
                (m.get("execution"), m.get("path"))
            {
                out.push((p.clone(), e.clone()));
            }
            m.values().for_each(|x| collect_executions(x, out));
        }
        Value::Array(a) => a.iter().for_each(|x| collect_executions(x, out)),
        _ => {}
    }
}

/// The largest |a - b| over channels `channels` of every pixel (rgba).
fn worst(a: &[f32], b: &[f32], channels: &[usize]) -> f32 {
    assert_eq!(a.len(), b.len(), "sizes differ");
    a.chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(x, y)| channels.iter().map(move |&c| (x[c] - y[c]).abs()))
        .fold(0.0, f32::max)
}

/// A copy of the pass under test into a 32-bit float image of its size.
const COPY: &str = "@group(0) @binding(0) var img: texture_2d<f32>;\n@fragment\nfn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {\n    return textureLoad(img, vec2<i32>(pos.xy), 0);\n}\n";

/// temporal_denoise's motion search (effects/temporal_denoise.fx) on its own:
/// the exhaustive coarsest level, a refined level and the full-resolution
/// refinement (against the previous input standing in for the filter's state),
/// every vector field of format FMT; the output is the finest field.
const MOTION: &str = "EFFECT.agree = {
    PASS = {
        y1 = SHADER.temporal_denoise_luma { img = IN  DEFINE.LUMA = 1  OUT.SCALE = 0.5  OUT.FORMAT = r16f }
        y2 = SHADER.temporal_denoise_luma { img = PASS.y1  OUT.SCALE = 0.5  OUT.RELATIVE_TO = img  OUT.FORMAT = r16f }
        mv2 = SHADER.temporal_denoise_match { cur = PASS.y2  prev = PASS.y2[-1]  last = PASS.mv2[-1]  DEFINE.COARSEST = 1  DEFINE.WINDOW = 3  DEFINE.RADIUS = 2  OUT.SCALE = 0.5  OUT.RELATIVE_TO = cur  OUT.FORMAT = FMT }
        mv1 = SHADER.temporal_denoise_match { cur = PASS.y1  prev = PASS.y1[-1]  last = PASS.mv1[-1]  coarse = PASS.mv2  DEFINE.WINDOW = 4  OUT.SCALE = 0.25  OUT.RELATIVE_TO = cur  OUT.FORMAT = FMT }
        p = SHADER.temporal_denoise_refine { cur = IN  hist = IN[-1]  coarse = PASS.mv1  OUT.SCALE = 0.125  OUT.FORMAT = FMT }
        q = SHADER.copy { img = PASS.p  OUT.SCALE = 1  OUT.RELATIVE_TO = img  OUT.FORMAT = rgba32f }
    }
    OUT = q
}
";

/// One pass `p` of format FMT on the input, copied out at its size.
fn single(pass: &str) -> String {
    format!("EFFECT.agree = {{\n    PASS = {{\n        p = {pass}  OUT.FORMAT = FMT }}\n        q = SHADER.copy {{ img = PASS.p  OUT.SCALE = 1  OUT.RELATIVE_TO = img  OUT.FORMAT = rgba32f }}\n    }}\n    OUT = q\n}}\n")
}

/// Measured on lavapipe: every case 0 (the motion vectors move up to 2.5 px a
/// frame, the tile footprints are 10 or 11 px wide: 96 x 0.09 = 8.64 tiles).
#[test]
fn tile_and_motion_search_compute_entry_points_agree_with_their_fragment_ones() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("seq")).unwrap();
    for t in 0..4 {
        save(&d.join(format!("seq/{t:04}.exr")), &frame(t));
    }
    std::fs::write(d.join("copy.wgsl"), COPY).unwrap();
    // (effect, the passes checked, whether it reads a sequence)
    let cases: [(String, &[&str], bool); 4] = [
        (
            single("SHADER.motion_blur_tilemax { motion = IN  OUT.SCALE = (0.09, 1)"),
            &["agree/p"],
            false,
        ),
        (
            single(
                "SHADER.motion_blur_tilemax { motion = IN  DEFINE.AXIS = 1  OUT.SCALE = (1, 0.09)",
            ),
            &["agree/p"],
            false,
        ),
        (
            single("SHADER.motion_blur_neighbor { tiles = IN"),
            &["agree/p"],
            false,
        ),
        (
            MOTION.to_string(),
            &["agree/mv2", "agree/mv1", "agree/p"],
            true,
        ),
    ];
    for (fx, passes, sequence) in cases {
        let mut images = Vec::new();
        for (format, runs_as) in [("rg32f", "compute"), ("rgba32f", "fragment")] {
            std::fs::write(d.join("agree.fx"), fx.replace("FMT", format)).unwrap();
            let (input, output, outputs) = match sequence {
                true => (
                    "seq/%04d.exr",
                    format!("{format}/%04d.exr"),
                    (1..4).map(|t| format!("{format}/{t:04}.exr")).collect(),
                ),
                false => (
                    "seq/0001.exr",
                    format!("{format}.exr"),
                    vec![format!("{format}.exr")],
                ),
            };
            let args = ["agree.fx", "-i", input, "--bit-depth", "32", "-o", &output];
            let (imgs, executions) = run(d, &args, &outputs, "compute");
            for pass in passes {
                let got = executions
                    .iter()
                    .find(|(p, _)| p == pass)
                    .map(|(_, e)| e.as_str());
                assert_eq!(got, Some(runs_as), "{pass} at {format}: {executions:?}");
            }
            images.push(imgs);
        }
        for (f, (a, b)) in images[0].iter().zip(&images[1]).enumerate() {
            let diff = worst(a, b, &[0, 1]);
            eprintln!("{passes:?} frame {f}: |compute - fragment entry point| = {diff:e}");
            assert_eq!(diff, 0.0, "{passes:?} frame {f}");
        }
    }
}

/// taa and motion_blur on three frames of the room seen by an orbiting camera
/// (motion everywhere, a history for taa), fragment against compute execution.
/// Fragment execution draws every pass of these two as a fragment pass but
/// motion_blur's neighbour maximum and taa's resolve (staged dispatches on both
/// paths); compute execution dispatches all of them, its own entry point for
/// the compute-native ones. Measured on lavapipe: 0 (taa), 0 (motion_blur).
#[test]
fn taa_and_motion_blur_agree_over_frames_of_a_moving_camera() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for effect in ["taa", "motion_blur"] {
        let mut images = Vec::new();
        for execution in ["fragment", "compute"] {
            let out = format!("{effect}-{execution}/%04d.exr");
            let args = [
                effect,
                "--scene",
                "builtin:room",
                "--size",
                "96x64",
                "--camera",
                "orbit:period=2",
                "--frames",
                "0..2",
                "-o",
                &out,
            ];
            let outputs: Vec<String> = (0..3)
                .map(|t| format!("{effect}-{execution}/{t:04}.exr"))
                .collect();
            let (imgs, executions) = run(d, &args, &outputs, execution);
            for (pass, e) in &executions {
                let want = match (execution, pass.as_str()) {
                    ("fragment", "motion_blur/neighbor" | "taa/resolve") | ("compute", _) => {
                        "compute"
                    }
                    _ => "fragment",
                };
                assert_eq!(e, want, "{effect} ({execution}): {pass}");
            }
            images.push(imgs);
        }
        for (f, (a, b)) in images[0].iter().zip(&images[1]).enumerate() {
            let diff = worst(a, b, &[0, 1, 2, 3]);
            eprintln!("{effect} frame {f}: |fragment - compute| = {diff:e}");
            assert!(diff <= 1e-3, "{effect} frame {f}: {diff}");
        }
    }
}

/// taa's resolve runs its `@compute` entry point on both execution paths, so its
/// `@fragment` one (the fallback where the state cannot be a storage texture)
/// is checked by a copy of taa whose resolve shader lacks the compute entry:
/// drawn under fragment execution, against the built-in taa's dispatch, over
/// three frames of an orbiting camera. Measured on lavapipe: 0.
#[test]
fn taa_resolve_fragment_entry_point_gives_the_compute_ones_image() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shader =
        std::fs::read_to_string(root.join("shaders/effects/taa/taa_resolve.wgsl")).unwrap();
    let cut = shader
        .find("\n// cs_main:")
        .expect("taa_resolve.wgsl's cs_main section");
    let fragment_only: String = shader[..cut]
        .lines()
        .filter(|l| !l.contains("texture_storage_2d"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::create_dir_all(d.join("copy")).unwrap();
    std::fs::write(d.join("copy/taa_resolve.wgsl"), fragment_only).unwrap();
    std::fs::copy(root.join("effects/taa.fx"), d.join("copy/taa.fx")).unwrap();
    let mut images = Vec::new();
    for (effect, runs_as) in [("taa", "compute"), ("copy/taa.fx", "fragment")] {
        let out = format!("{runs_as}/%04d.exr");
        let args = [
            effect,
            "--scene",
            "builtin:room",
            "--size",
            "96x64",
            "--camera",
            "orbit:period=2",
            "--frames",
            "0..2",
            "-o",
            &out,
        ];
        let outputs: Vec<String> = (0..3).map(|t| format!("{runs_as}/{t:04}.exr")).collect();
        let (imgs, executions) = run(d, &args, &outputs, "fragment");
        let got = executions
            .iter()
            .find(|(p, _)| p == "taa/resolve")
            .map(|(_, e)| e.as_str());
        assert_eq!(got, Some(runs_as), "{effect}: {executions:?}");
        images.push(imgs);
    }
    for (f, (a, b)) in images[0].iter().zip(&images[1]).enumerate() {
        let diff = worst(a, b, &[0, 1, 2, 3]);
        eprintln!("taa frame {f}: |compute - fragment entry point| = {diff:e}");
        assert_eq!(diff, 0.0, "taa frame {f}");
    }
}

/// temporal_denoise's noise estimate (effects/temporal_denoise.fx) on its own:
/// residuals, block means and the 1x1 estimate (with its temporal smoothing,
/// `last`) of format FMT, copied out.
const NOISE: &str = "EFFECT.agree = {
    PASS = {
        nres = SHADER.temporal_denoise_noise_residual { img = IN  OUT.SCALE = 0.25  OUT.FORMAT = rg16f }
        nblk = SHADER.temporal_denoise_noise_blocks { img = PASS.nres  OUT.SCALE = 0.25  OUT.RELATIVE_TO = img  OUT.FORMAT = rg16f }
        p = SHADER.temporal_denoise_noise_estimate { blk = PASS.nblk  last = PASS.p[-1]  OUT.SIZE = (1, 1)  OUT.FORMAT = FMT }
        q = SHADER.copy { img = PASS.p  OUT.SCALE = 1  OUT.RELATIVE_TO = img  OUT.FORMAT = rgba32f }
    }
    OUT = q
}
";

/// A 400x272 frame `t` (25 x 17 = 425 blocks of 16 px: more than the compute
/// entry point's 256 lanes): a texture on the left, a flat grey on the right,
/// uniform noise of 3/255 (amplitude growing with t), and clipped bands (black
/// and white) whose blocks the estimate leaves out. With `clipped`, a black
/// pixel every 8 on each axis but in the top-left 32 x 64 pixels clips all
/// blocks but 4 there (fewer than 8 unclipped: every block counts).
fn noise_frame(t: u32, clipped: bool) -> fxgraph::io::Image {
    let (w, h) = (400u32, 272u32);
    let amp = (3.0 + t as f32) / 255.0 * 3f32.sqrt();
    let mut px = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let k = u64::from((t * h + y) * w + x);
            let n = |c: u64| amp * (2.0 * common::rng::hash01(3 * k + c) - 1.0);
            let base = if x < 200 {
                0.5 + 0.25 * (x as f32 * 0.21).sin() * (y as f32 * 0.13).cos()
            } else {
                0.4
            };
            let dot = clipped && x % 8 == 0 && y % 8 == 0 && !(x < 32 && y < 64);
            let v = if dot || (40..60).contains(&y) {
                [0.0; 3]
            } else if (200..216).contains(&y) {
                [1.0; 3]
            } else {
                [base + n(0), base + n(1), base + n(2)]
            };
            px.extend([v[0], v[1], v[2], 1.0]);
        }
    }
    common::samples::float_image(w, h, px)
}

/// The compute entry point (one workgroup, the counts of each bisection step
/// summed in workgroup memory) gives exactly what the fragment one (one
/// invocation counting every block) gives: integer counts, an exact maximum,
/// the same bisection. Over three frames (the smoothing with `last`), with
/// clipped blocks left out, and with nearly every block clipped (all counted).
#[test]
fn noise_estimate_compute_entry_point_agrees_with_its_fragment_one() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("copy.wgsl"), COPY).unwrap();
    for clipped in [false, true] {
        let seq = format!("seq{}", u8::from(clipped));
        std::fs::create_dir_all(d.join(&seq)).unwrap();
        for t in 0..3 {
            save(
                &d.join(format!("{seq}/{t:04}.exr")),
                &noise_frame(t, clipped),
            );
        }
        let mut images = Vec::new();
        for (format, runs_as) in [("r32f", "compute"), ("rgba32f", "fragment")] {
            std::fs::write(d.join("agree.fx"), NOISE.replace("FMT", format)).unwrap();
            let input = format!("{seq}/%04d.exr");
            let output = format!("{seq}-{format}/%04d.exr");
            let outputs: Vec<String> = (0..3)
                .map(|t| format!("{seq}-{format}/{t:04}.exr"))
                .collect();
            let args = ["agree.fx", "-i", &input, "--bit-depth", "32", "-o", &output];
            let (imgs, executions) = run(d, &args, &outputs, "compute");
            let got = executions
                .iter()
                .find(|(p, _)| p == "agree/p")
                .map(|(_, e)| e.as_str());
            assert_eq!(got, Some(runs_as), "{seq} at {format}: {executions:?}");
            images.push(imgs);
        }
        for (f, (a, b)) in images[0].iter().zip(&images[1]).enumerate() {
            let sigma = a[0] * 255.0;
            eprintln!(
                "{seq} frame {f}: estimate {sigma:.3}/255 (compute), {:.3}/255 (fragment)",
                b[0] * 255.0
            );
            assert!(
                sigma > 0.0 && sigma < 50.0,
                "{seq} frame {f}: estimate {sigma}/255"
            );
            assert_eq!(a[0], b[0], "{seq} frame {f}");
        }
    }
}
