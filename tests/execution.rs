//! The two execution paths give the same images (docs/architecture.md,
//! "Execution paths"): every built-in effect, a user shader, effects with history
//! and feedback, and the G-buffer effects of a rendered scene run with
//! `--execution fragment` and `--execution compute`, and the outputs agree within
//! 1e-3 in float (EXR outputs) and 1 LSB at 8 bits (PNG outputs). The reference
//! is the fragment path, which the effects' own oracle tests check; the timings
//! JSON shows which path each pass took, so a silent fall-back to fragment fails.

use crate::common;

use common::cli::{command, save};
use fxgraph::gpu::context::{require_gpu, AdapterChoice, GpuContext};
use fxgraph::io::{load_image, Image, LoadOptions, Pixels};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Effects that read a still image (no AUX inputs, no other frames).
const STILL_EFFECTS: &[&str] = &[
    "bloom",
    "chroma_key",
    "color_grade",
    "edges",
    "format_convert",
    "fxaa",
    "gaussian_blur",
    "glow",
    "pencil",
    "sharpen",
    "tonemap",
    "vignette",
];

/// Effects with history (`IN[-n]`) or feedback (`PASS.x[-1]`), run on a sequence.
const TEMPORAL_EFFECTS: &[&str] = &[
    "auto_exposure",
    "chroma_key_temporal",
    "deinterlace",
    "frame_blend",
    "motion_trail",
    "temporal_denoise",
];

/// Effects reading the renderer's G-buffer (`AUX.*`), run on a rendered scene.
const SCENE_EFFECTS: &[&str] = &[
    "dof",
    "fog",
    "motion_blur",
    "outline",
    "ssao",
    "ssgi",
    "taa",
];

/// Passes written as compute passes (`@compute` shaders): compute on both paths
/// (temporal_denoise's `nsig`: one workgroup for its 1x1 output, where its
/// fragment entry point is one invocation; tests/compute_native.rs compares the
/// two). (The reductions, auto_exposure's m1 and m2 and tonemap's p1 and p2,
/// motion_blur's tile maxima and temporal_denoise's motion search are compute
/// passes drawn as fragment passes under fragment execution;
/// tests/compute_native.rs compares those entry points.)
/// (gaussian_blur's `vertical`, sharpen's `sharpen`, pencil's blurs and the
/// G-buffer blurs of ssao and ssgi are marked `// @execution(compute)`: their
/// compute entry points run under compute execution, which `compare` checks,
/// and their fragment ones under fragment execution.)
const NATIVE: &[&str] = &[
    "gaussian_blur/horizontal",
    "sharpen/blur",
    "glow/blurX",
    "glow/blurY",
    "dof/nearmax_h",
    "dof/nearmax_v",
    "motion_blur/neighbor",
    "taa/resolve",
    "temporal_denoise/nsig",
];

/// Float outputs agree within this (absolute, per channel).
const FLOAT_TOLERANCE: f32 = 1e-3;

/// The tolerance of an effect's float output. chroma_key_temporal keys into an
/// `rgba8-srgb` texture: the compute path encodes sRGB in the shader where the
/// fragment path's hardware does, and the two may round one 8-bit level apart.
/// Decoded to linear near 1.0 one level is 2.4 / 1.055 / 255 = 0.0089, so the
/// float output agrees within 1 LSB at 8 bits of that intermediate: 0.01.
fn tolerance(effect: &str) -> f32 {
    match effect {
        "chroma_key_temporal" => 0.01,
        _ => FLOAT_TOLERANCE,
    }
}

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

/// A 96x64 test picture: gradients, a bright disc and thin lines (edges, keys
/// and blurs all have something to do), shifted by `t` pixels.
fn picture(t: u32) -> Image {
    let (w, h) = (96u32, 64u32);
    let mut px = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let xs = (x + t) as f32;
            let d = ((xs - 40.0).powi(2) + (y as f32 - 30.0).powi(2)).sqrt();
            let disc = if d < 12.0 { 1.0 } else { 0.0 };
            let line = if (x + t) % 11 == 0 || y % 13 == 0 {
                0.8
            } else {
                0.0
            };
            let r = (xs / w as f32 * 0.7 + disc * 0.3 + line * 0.2).min(1.0);
            let g = (y as f32 / h as f32 * 0.6 + line).min(1.0);
            let b = (0.2 + 0.6 * disc + 0.1 * ((xs * 0.3).sin() + 1.0)).min(1.0);
            px.extend([r, g, b, 1.0]);
        }
    }
    common::samples::float_image(w, h, px)
}

/// The outputs of one run, in float, and the execution of every pass it timed.
struct Run {
    images: Vec<Vec<f32>>,
    executions: Vec<(String, String)>,
}

fn run(dir: &Path, tag: &str, args: &[&str], outputs: &[&str], execution: &str) -> Run {
    let json = dir.join(format!("{tag}-{execution}.json"));
    let mut all: Vec<String> = args.iter().map(|s| s.replace("EXEC", execution)).collect();
    all.extend([
        "--execution".into(),
        execution.into(),
        "--timings".into(),
        "--timings-json".into(),
        json.display().to_string(),
    ]);
    let o = command(&all).current_dir(dir).output().expect("run fxrun");
    assert!(
        o.status.success(),
        "{tag} ({execution}): {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let images = outputs
        .iter()
        .map(|name| {
            let path = dir.join(name.replace("EXEC", execution));
            let img = load_image(&path, &LoadOptions::default())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            to_f32(&img)
        })
        .collect();
    let report: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let mut executions = Vec::new();
    collect_executions(&report, &mut executions);
    Run { images, executions }
}

fn to_f32(img: &Image) -> Vec<f32> {
    match &img.pixels {
        Pixels::F32(v) => v.clone(),
        Pixels::U8(v) => v.iter().map(|&b| f32::from(b) / 255.0).collect(),
    }
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

/// Runs `args` both ways and compares every output; returns the largest
/// difference. `tolerance` is per channel; the compute run must have dispatched
/// every pass as compute but for at most `fragment_ok` of them.
fn compare(
    dir: &Path,
    tag: &str,
    args: &[&str],
    outputs: &[&str],
    tolerance: f32,
    fragment_ok: usize,
) -> f32 {
    let f = run(dir, tag, args, outputs, "fragment");
    let c = run(dir, tag, args, outputs, "compute");
    assert!(
        f.executions
            .iter()
            .all(|(p, e)| e == "fragment" || NATIVE.iter().any(|n| p.ends_with(n))),
        "{tag}: fragment run dispatched compute: {:?}",
        f.executions
    );
    assert!(!c.executions.is_empty(), "{tag}: no pass timings");
    let fragment: Vec<&String> = c
        .executions
        .iter()
        .filter(|(_, e)| e != "compute")
        .map(|(p, _)| p)
        .collect();
    assert!(
        fragment.len() <= fragment_ok,
        "{tag}: passes {fragment:?} ran as fragment passes under --execution compute"
    );
    let mut worst = 0.0f32;
    for (i, (a, b)) in f.images.iter().zip(&c.images).enumerate() {
        assert_eq!(a.len(), b.len(), "{tag} output {i}: sizes differ");
        let (at, d) = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .enumerate()
            .fold((0, 0.0f32), |m, (j, d)| if d > m.1 { (j, d) } else { m });
        assert!(
            d <= tolerance,
            "{tag} output {i}: |fragment - compute| = {d} at sample {at} (tolerance {tolerance})"
        );
        worst = worst.max(d);
    }
    eprintln!("{tag}: max |fragment - compute| = {worst:.2e}");
    worst
}

fn temp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn every_still_effect_gives_the_same_float_image() {
    if !gpu() {
        return;
    }
    let dir = temp();
    save(&dir.path().join("in.exr"), &picture(0));
    for effect in STILL_EFFECTS {
        let out = format!("{effect}-EXEC.exr");
        let args = [*effect, "-i", "in.exr", "-o", &out];
        let args: Vec<&str> = args.to_vec();
        // The EXR path writes rgba16f/32f, which every adapter can store to.
        compare(dir.path(), effect, &args, &[&out], FLOAT_TOLERANCE, 0);
    }
}

#[test]
fn eight_bit_outputs_agree_within_one_level() {
    if !gpu() {
        return;
    }
    let dir = temp();
    save(&dir.path().join("in.png"), &picture(3));
    for effect in ["glow", "gaussian_blur", "pencil", "sharpen", "tonemap"] {
        // The output texture of an 8-bit file is sRGB-encoded by its format,
        // which no adapter stores to: the last pass writes a stand-in in the
        // raw format (encoding sRGB in the shader; gaussian_blur's compute-native
        // `vertical` stores rgba16float, converted after it), copied into the
        // output. No pass stays a fragment pass.
        eight_bit_agree(dir.path(), effect, &["-i", "in.png"]);
    }
}

/// `effect` with `source` (its input arguments) into a PNG under both
/// execution paths: within one 8-bit level, no pass drawn under compute.
fn eight_bit_agree(dir: &Path, effect: &str, source: &[&str]) {
    let out = format!("{effect}-EXEC.png");
    let mut args = vec![effect];
    args.extend_from_slice(source);
    args.extend(["-o", &out]);
    let d = compare(dir, effect, &args, &[&out], 1.0 / 255.0 + 1e-6, 0);
    assert!(d <= 1.0 / 255.0 + 1e-6);
}

/// SSAO's and SSGI's last passes are compute-native and store rgba16float:
/// into an 8-bit sRGB file their values are converted (sRGB-encoded) after the
/// dispatch, within one level of the fragment entry point drawn into the sRGB
/// target.
#[test]
fn eight_bit_outputs_of_compute_native_passes_are_converted() {
    if !gpu() {
        return;
    }
    let dir = temp();
    for effect in ["ssao", "ssgi"] {
        let scene = ["--scene", "builtin:room", "--size", "96x64"];
        eight_bit_agree(dir.path(), effect, &scene);
    }
}

#[test]
fn a_user_shader_runs_as_compute() {
    if !gpu() {
        return;
    }
    let dir = temp();
    save(&dir.path().join("in.exr"), &picture(1));
    // A shader of the user's: a helper function sampling with implicit
    // derivatives, `pos` and `uv` both read, a parameter.
    let wgsl = r#"
struct Params { gain: f32, }
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var img_sampler: sampler;
@group(0) @binding(2) var<uniform> params: Params;
fn tap(uv: vec2<f32>, d: vec2<f32>) -> vec4<f32> {
    return textureSample(img, img_sampler, uv + d);
}
@fragment
fn fs_main(@location(0) uv: vec2<f32>, @builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let px = 1.0 / vec2<f32>(textureDimensions(img));
    let c = 0.5 * tap(uv, vec2<f32>(0.0)) + 0.25 * (tap(uv, vec2<f32>(px.x, 0.0)) + tap(uv, vec2<f32>(0.0, px.y)));
    let checker = f32((u32(pos.x) + u32(pos.y)) % 2u);
    return vec4<f32>(c.rgb * params.gain + 0.01 * checker, 1.0);
}
"#;
    let fx = "EFFECT.mine = {\n    PASS = {\n        p = SHADER.mine { img = IN\n gain = 1.5 }\n    }\n    OUT = p\n}\n";
    let effect = common::cli::write_effect(dir.path(), "mine", fx, ("mine", wgsl));
    let args = [effect.as_str(), "-i", "in.exr", "-o", "mine-EXEC.exr"];
    compare(
        dir.path(),
        "user shader",
        &args,
        &["mine-EXEC.exr"],
        FLOAT_TOLERANCE,
        0,
    );
}

/// Numbered EXR frames of a moving picture with noise that changes every
/// frame (±0.1, a fixed hash): `dir/seq/0000.exr` ... The noise gives motion
/// searches and keys discrete choices to make, where a last-bit difference
/// between the paths would show (temporal_denoise's luma levels sampled at the
/// interpolated `uv` made its outputs differ by up to 0.17).
fn sequence(dir: &Path, frames: u32) -> PathBuf {
    let seq = dir.join("seq");
    std::fs::create_dir_all(&seq).unwrap();
    for i in 0..frames {
        let mut img = picture(2 * i);
        if let Pixels::F32(px) = &mut img.pixels {
            for (k, v) in px.iter_mut().enumerate().filter(|(k, _)| k % 4 != 3) {
                let h = (k as u32 ^ i.wrapping_mul(0x9e37_79b9)).wrapping_mul(0x85eb_ca6b);
                let n = (h >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
                *v = (*v + 0.2 * n).clamp(0.0, 1.0);
            }
        }
        save(&seq.join(format!("{i:04}.exr")), &img);
    }
    seq
}

#[test]
fn history_and_feedback_effects_agree_frame_by_frame() {
    if !gpu() {
        return;
    }
    let dir = temp();
    let frames = 4;
    sequence(dir.path(), frames);
    for effect in TEMPORAL_EFFECTS {
        let out = format!("{effect}-EXEC/%04d.exr");
        let outputs: Vec<String> = (0..frames)
            .map(|i| format!("{effect}-EXEC/{i:04}.exr"))
            .collect();
        let outputs: Vec<&str> = outputs.iter().map(String::as_str).collect();
        let args = [*effect, "-i", "seq/%04d.exr", "-o", &out];
        compare(dir.path(), effect, &args, &outputs, tolerance(effect), 0);
    }
}

#[test]
fn gbuffer_effects_of_a_rendered_scene_agree() {
    if !gpu() {
        return;
    }
    let dir = temp();
    for effect in SCENE_EFFECTS {
        let out = format!("{effect}-EXEC.exr");
        let args = [
            *effect,
            "--scene",
            "builtin:room",
            "--size",
            "96x64",
            "-o",
            &out,
        ];
        compare(dir.path(), effect, &args, &[&out], FLOAT_TOLERANCE, 0);
    }
}

/// The rule `auto` applies, as the run reports it: fragment on this machine's
/// CPU adapter (lavapipe), compute on hardware GPUs; compute passes are compute.
#[test]
fn auto_is_fragment_on_a_cpu_adapter() {
    let Ok(ctx) = GpuContext::new(&AdapterChoice::Auto) else {
        assert!(!require_gpu());
        return;
    };
    let want = if ctx.info.device_type == wgpu::DeviceType::Cpu {
        "fragment"
    } else {
        "compute"
    };
    let dir = temp();
    save(&dir.path().join("in.exr"), &picture(0));
    let r = run(
        dir.path(),
        "auto",
        &["glow", "-i", "in.exr", "-o", "auto-EXEC.exr"],
        &["auto-auto.exr"],
        "auto",
    );
    // Compute passes (glow's blurs) are compute on either path.
    assert!(
        r.executions
            .iter()
            .all(|(p, e)| if NATIVE.iter().any(|n| p.ends_with(n)) {
                e == "compute"
            } else {
                e == want
            }),
        "{:?}",
        r.executions
    );
}

/// Auto never enumerates GL adapters when a native (Vulkan) one exists:
/// creating the GL instance costs every run tens of milliseconds.
#[test]
fn no_gl_enumeration_when_vulkan_has_an_adapter() {
    let Ok(ctx) = GpuContext::new(&AdapterChoice::Auto) else {
        assert!(!require_gpu());
        return;
    };
    if ctx.info.backend == wgpu::Backend::Vulkan {
        assert!(
            !ctx.enumerated.contains(wgpu::Backends::GL),
            "enumerated {:?}",
            ctx.enumerated
        );
    }
    assert!(ctx
        .enumerated
        .contains(wgpu::Backends::from(ctx.info.backend)));
}

/// A compute pass of the user's (`@compute` and a storage output) runs on both
/// execution paths and matches its CPU oracle (2 × the input, within the
/// rounding of the rgba16f output);
/// one whose storage format is not the pass's format is refused with the
/// pass, the variable and both formats named.
#[test]
fn a_user_compute_pass_runs_and_a_wrong_storage_format_is_named() {
    if !gpu() {
        return;
    }
    let dir = temp();
    let input = picture(5);
    save(&dir.path().join("in.exr"), &input);
    let wgsl = |format: &str| {
        format!(
            r#"
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var out: texture_storage_2d<{format}, write>;
@compute @workgroup_size(8, 4, 1)
fn twice(@builtin(global_invocation_id) id: vec3<u32>) {{
    let size = textureDimensions(img);
    if id.x >= size.x || id.y >= size.y {{
        return;
    }}
    textureStore(out, id.xy, 2.0 * textureLoad(img, id.xy, 0));
}}
"#
        )
    };
    let fx = "EFFECT.twice = {\n    PASS = {\n        p = SHADER.twice { img = IN\n OUT.FORMAT = rgba16f }\n    }\n    OUT = p\n}\n";
    let effect =
        common::cli::write_effect(dir.path(), "twice", fx, ("twice", &wgsl("rgba16float")));
    let want: Vec<f32> = to_f32(&input).iter().map(|v| 2.0 * v).collect();
    for execution in ["fragment", "compute"] {
        let args = [effect.as_str(), "-i", "in.exr", "-o", "twice-EXEC.exr"];
        let r = run(dir.path(), "twice", &args, &["twice-EXEC.exr"], execution);
        assert_eq!(
            r.executions,
            [("twice/p".to_string(), "compute".to_string())]
        );
        let worst = r.images[0]
            .iter()
            .zip(&want)
            .map(|(g, w)| (g - w).abs() / w.abs().max(1e-3))
            .fold(0.0f32, f32::max);
        // rgba16f keeps 11 significant bits: a relative error of at most 2^-11.
        assert!(
            worst <= 1.0 / 2048.0,
            "{execution}: relative error {worst} from 2 x the input"
        );
    }
    std::fs::write(dir.path().join("twice.wgsl"), wgsl("rgba32float")).unwrap();
    let o = command([effect.as_str(), "-i", "in.exr", "-o", "bad.exr"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("twice.fx:3:9")
            && err.contains("`out`")
            && err.contains("rgba16f")
            && err.contains("rgba32float"),
        "{err}"
    );
    assert!(!dir.path().join("bad.exr").exists());
}

/// A shader with a `@compute` and a `@fragment` entry point: the compute one
/// runs where the pass's output can be a storage texture (rgba16f), on both
/// execution paths; the fragment one is drawn where it cannot (an `rgba8-srgb`
/// pass). Two passes of it give 2 min(2 x, 1).
/// A shader doubling its input, with both entry points.
const TWICE_BOTH: &str = r#"
@group(0) @binding(0) var img: texture_2d<f32>;
@group(0) @binding(1) var out: texture_storage_2d<rgba16float, write>;
@compute @workgroup_size(8, 4, 1)
fn twice(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(img);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    textureStore(out, id.xy, 2.0 * textureLoad(img, id.xy, 0));
}
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return 2.0 * textureLoad(img, vec2<i32>(pos.xy), 0);
}
"#;

/// `// @execution(compute)` keeps a compute entry point to compute execution:
/// fragment execution draws the fragment one (both double the input); without
/// a fragment entry point the line is an error naming it.
#[test]
fn a_compute_entry_point_marked_for_compute_execution_is_drawn_under_fragment() {
    if !gpu() {
        return;
    }
    let dir = temp();
    let input = picture(1);
    save(&dir.path().join("in.exr"), &input);
    let wgsl = TWICE_BOTH.replace("@compute", "// @execution(compute)\n@compute");
    let fx = "EFFECT.marked = {\n    PASS = {\n        q = SHADER.marked { img = IN  OUT.FORMAT = rgba16f }\n    }\n    OUT = q\n}\n";
    let effect = common::cli::write_effect(dir.path(), "marked", fx, ("marked", &wgsl));
    let want: Vec<f32> = to_f32(&input).iter().map(|v| 2.0 * v).collect();
    for execution in ["fragment", "compute"] {
        let args = [effect.as_str(), "-i", "in.exr", "-o", "marked-EXEC.exr"];
        let r = run(dir.path(), "marked", &args, &["marked-EXEC.exr"], execution);
        assert_eq!(
            r.executions,
            [("marked/q".to_string(), execution.to_string())]
        );
        // rgba16f keeps 11 significant bits: 2^-11 of at most 2.
        let worst = r.images[0]
            .iter()
            .zip(&want)
            .map(|(g, w)| (g - w).abs())
            .fold(0.0f32, f32::max);
        assert!(worst <= 1e-3, "{execution}: error {worst} from 2 x");
    }
    let compute_only = wgsl.split("@fragment").next().unwrap().to_string();
    let effect = common::cli::write_effect(dir.path(), "marked", fx, ("marked", &compute_only));
    let o = command([effect.as_str(), "-i", "in.exr", "-o", "x.exr"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "ran without a fragment entry point");
    assert!(
        err.contains("marked.wgsl:4:1:") && err.contains("no `@fragment` entry point"),
        "{err}"
    );
}

#[test]
fn a_compute_pass_with_a_fragment_entry_point_draws_it_where_compute_cannot_run() {
    if !gpu() {
        return;
    }
    let dir = temp();
    let input = picture(2);
    save(&dir.path().join("in.exr"), &input);
    let wgsl = TWICE_BOTH;
    let fx = "EFFECT.both = {\n    PASS = {\n        p = SHADER.both { img = IN  OUT.FORMAT = rgba8-srgb }\n        q = SHADER.both { img = PASS.p  OUT.FORMAT = rgba16f }\n    }\n    OUT = q\n}\n";
    let effect = common::cli::write_effect(dir.path(), "both", fx, ("both", wgsl));
    let want: Vec<f32> = to_f32(&input)
        .iter()
        .map(|v| 2.0 * (2.0 * v).min(1.0))
        .collect();
    for execution in ["fragment", "compute"] {
        let args = [effect.as_str(), "-i", "in.exr", "-o", "both-EXEC.exr"];
        let r = run(dir.path(), "both", &args, &["both-EXEC.exr"], execution);
        let runs = |p: &str, e: &str| (p.to_string(), e.to_string());
        assert_eq!(
            r.executions,
            [runs("both/p", "fragment"), runs("both/q", "compute")]
        );
        // p stores 8-bit sRGB levels: within one level (the encode need not
        // round to nearest; 0.0111 measured on lavapipe), 2.4 / 1.055 / 255 =
        // 0.0089 in linear light near 1, doubled by q; q's rgba16f keeps 11
        // significant bits (2^-11 of at most 2): 0.0178 + 0.001.
        let worst = r.images[0]
            .iter()
            .zip(&want)
            .map(|(g, w)| (g - w).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst <= 0.019,
            "{execution}: error {worst} from 2 min(2 x, 1)"
        );
    }
}

/// The largest difference of `a` from `b`, relative to max(|b|, 1), over the
/// channels `c` of each pixel.
fn worst_relative(a: &[f32], b: &[f32], channels: &[usize]) -> f32 {
    a.chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(x, y)| {
            channels
                .iter()
                .map(move |&c| (x[c] - y[c]).abs() / y[c].abs().max(1.0))
        })
        .fold(0.0, f32::max)
}

/// One shader with both entry points, run both ways by
/// [`compute_passes_agree_with_their_fragment_entry_points`].
struct Agree {
    /// The input: an image (`-i in.exr`) or a rendered scene (AUX images).
    input: &'static [&'static str],
    shader: &'static str,
    settings: &'static str,
    /// The pass's storage format (runs the compute entry point) and another
    /// (runs the fragment one).
    storage: &'static str,
    other: &'static str,
    /// The channels compared and the bound on their relative difference.
    channels: &'static [usize],
    bound: f32,
}

const IMAGE: &[&str] = &["-i", "in.exr"];
const SCENE: &[&str] = &["--scene", "builtin:room", "--size", "96x64"];
const RGBA: &[usize] = &[0, 1, 2, 3];

const fn agree(
    input: &'static [&'static str],
    shader: &'static str,
    settings: &'static str,
    storage: &'static str,
    other: &'static str,
    channels: &'static [usize],
    bound: f32,
) -> Agree {
    Agree {
        input,
        shader,
        settings,
        storage,
        other,
        channels,
        bound,
    }
}

/// The shaders with both entry points and the settings they are compared at.
const AGREE: &[Agree] = &[
    agree(IMAGE, "blurX", "img = IN  OUT.SCALE = 0.5  sigma = 3", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "blurY", "img = IN  sigma = 2.5", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "blurY", "img = IN  OUT.SCALE = 0.5  sigma = 1.5", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "auto_exposure_meter", "img = IN  DEFINE.FIRST = 1  OUT.SCALE = 0.125", "rg32f", "rgba32f", &[0, 1], 1e-5),
    agree(IMAGE, "tonemap_peak", "img = IN  DEFINE.FIRST = 1  exposure = 2  OUT.SCALE = 0.125", "rgba32f", "rg32f", &[0, 1], 1e-5),
    agree(IMAGE, "tonemap_peak", "img = IN  exposure = 2  OUT.SIZE = (1, 1)", "rgba32f", "rg32f", &[0, 1], 1e-5),
    agree(IMAGE, "dof_nearmax", "src = PASS.n  max_radius = 5.5", "r16f", "rgba16f", &[0], 0.0),
    agree(IMAGE, "dof_nearmax", "src = IN  max_radius = 40  DEFINE.VERTICAL = 1", "r16f", "rgba16f", &[0], 0.0),
    agree(IMAGE, "gaussian_blur_rows", "img = IN  sigma = 3.5", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "gaussian_blur", "img = PASS.n  sigma = 3.5  DEFINE.VERTICAL = 1", "rgba16f", "rgba32f", RGBA, 1e-3),
    // A radius (60) past one round of the column window (48).
    agree(IMAGE, "gaussian_blur", "img = IN  sigma = 20  DEFINE.VERTICAL = 1  DEFINE.EXACT = 1", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "gaussian_blur", "img = IN  sigma = 1.5  DEFINE.VERTICAL = 0", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "gaussian_blur", "img = PASS.n  orig = IN  sigma = 2  amount = 1.5  threshold = 0  DEFINE.VERTICAL = 1  DEFINE.UNSHARP = 1  DEFINE.EXACT = 1", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(IMAGE, "pencil_blur", "img = IN  sigma = 5  scale = 0.5  OUT.SCALE = 0.5", "r16f", "r32f", &[0], 1e-3),
    agree(IMAGE, "pencil_blur", "img = PASS.n  sigma = 7  DEFINE.VERTICAL = 1", "r16f", "r32f", &[0], 1e-3),
    // Taps reaching past the staged window (r = 300): sampled as fs_main does.
    agree(IMAGE, "pencil_blur", "img = IN  sigma = 100  DEFINE.VERTICAL = 1", "r16f", "r32f", &[0], 1e-3),
    agree(SCENE, "ssao_blur", "img = IN  ao = PASS.n  depth = AUX.depth  normal = AUX.normal  depth_tolerance = 0.05", "rgba16f", "rgba32f", RGBA, 1e-3),
    agree(SCENE, "ssgi_out", "img = IN  gi = PASS.n  depth = AUX.depth  normal = AUX.normal  albedo = AUX.albedo  intensity = 2", "rgba16f", "rgba32f", RGBA, 1e-3),
];

/// The built-in shaders with both entry points (glow's blurs, the metering and
/// peak reductions, dof's near-field maximum filter, gaussian_blur's rows and
/// columns, pencil's blurs, the G-buffer blurs of ssao and ssgi) give the same
/// image from either: under compute execution each pass runs once at its
/// storage format (the compute entry point) and once at another (the fragment
/// one), copied to a 32-bit EXR. Measured on lavapipe: blurs 4.9e-4 relative
/// (the rgba16f rounding of the compute run, 2^-11 = 4.9e-4, and at the same
/// size the bilinear pairs of the fragment blur against exact taps;
/// gaussian_blur's rows: the rgba16f rounding alone; gaussian_blur's columns
/// 2.4e-4 to 4.9e-4, its unsharp mask 9.2e-4 (one rgba16f step is 2^-10
/// relative: lavapipe's stores round towards zero); pencil's blurs 2.4e-4 to
/// 4.9e-4 (r16f); the G-buffer blurs of ssao 7.9e-4 and ssgi 7.1e-4: the same
/// arithmetic, the rgba16f step alone), reductions 5.7e-7 (the order of the f32 sums), dof's
/// near-field maximum filter 0 (comparisons only; r16f and rgba16f round the
/// same); the bounds are 1e-3, 1e-5 and 0.
#[test]
fn compute_passes_agree_with_their_fragment_entry_points() {
    if !gpu() {
        return;
    }
    let dir = temp();
    save(&dir.path().join("in.exr"), &picture(3));
    let copy = "@group(0) @binding(0) var img: texture_2d<f32>;\n@fragment\nfn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {\n    return textureLoad(img, vec2<i32>(pos.xy), 0);\n}\n";
    std::fs::write(dir.path().join("copy.wgsl"), copy).unwrap();
    // Values of both signs (dof's near field is the negative CoC).
    let signs = copy.replace("return textureLoad", "return vec4<f32>(0.5) - textureLoad");
    std::fs::write(dir.path().join("signs.wgsl"), signs).unwrap();
    for case in AGREE {
        let images = [(case.storage, "compute"), (case.other, "fragment")]
            .map(|(format, runs_as)| agree_run(dir.path(), case, format, runs_as));
        let d = worst_relative(&images[0], &images[1], case.channels);
        let (shader, settings, bound) = (case.shader, case.settings, case.bound);
        eprintln!("{shader} {settings}: compute against fragment entry point {d:.2e}");
        assert!(d <= bound, "{shader} {settings}: {d} (bound {bound})");
    }
}

/// `case`'s pass at `format` under compute execution, which must run as
/// `runs_as`: its output in float.
fn agree_run(dir: &Path, case: &Agree, format: &str, runs_as: &str) -> Vec<f32> {
    let (shader, settings) = (case.shader, case.settings);
    let fx = format!("EFFECT.agree = {{\n    PASS = {{\n        n = SHADER.signs {{ img = IN  OUT.FORMAT = rgba32f }}\n        p = SHADER.{shader} {{ {settings}  OUT.FORMAT = {format} }}\n        q = SHADER.copy {{ img = PASS.p  OUT.FORMAT = rgba32f }}\n    }}\n    OUT = q\n}}\n");
    std::fs::write(dir.join("agree.fx"), fx).unwrap();
    let mut args = vec!["agree.fx"];
    args.extend(case.input);
    args.extend(["--bit-depth", "32", "-o", "agree-EXEC.exr"]);
    let r = run(dir, "agree", &args, &["agree-EXEC.exr"], "compute");
    let want = ("agree/p".to_string(), runs_as.to_string());
    let got = r.executions.iter().find(|(p, _)| p == "agree/p");
    assert_eq!(got, Some(&want), "{shader} {settings} {format}");
    r.images.into_iter().next().unwrap()
}

/// The pipeline cache is kept on disk where the backend has one (Vulkan), named
/// by adapter and driver, and not with FX_PIPELINE_CACHE=0; a damaged file does
/// not stop a run (the driver rejects it and starts empty).
#[test]
fn the_pipeline_cache_is_kept_on_disk() {
    let Ok(ctx) = GpuContext::new(&AdapterChoice::Auto) else {
        assert!(!require_gpu());
        return;
    };
    if !ctx.has_pipeline_cache_feature() {
        return;
    }
    let dir = temp();
    save(&dir.path().join("in.png"), &picture(0));
    let cache = dir.path().join("cache");
    let run = |off: bool| {
        let mut c = command(["glow", "-i", "in.png", "-o", "out.png"]);
        c.current_dir(dir.path()).env("FX_CACHE_DIR", &cache);
        if off {
            c.env("FX_PIPELINE_CACHE", "0");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(true);
    assert!(!cache.exists(), "FX_PIPELINE_CACHE=0 wrote a cache");
    run(false);
    let key = ctx.pipeline_cache_key().expect("a key on this backend");
    let file = cache.join(&key);
    assert!(file.is_file(), "no {}", file.display());
    std::fs::write(&file, b"not a pipeline cache").unwrap();
    run(false);
    assert_ne!(std::fs::read(&file).unwrap(), b"not a pipeline cache");
}
