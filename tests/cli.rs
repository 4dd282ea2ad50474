//! The real `fxrun` binary: exit codes, atomic writes, rejected inputs, analysis
//! modes, and snapshots of shader diagnostics.

mod common;

use common::cli::{code, fxrun, stderr};

use std::path::{Path, PathBuf};
use std::process::Command;

/// True when GPU tests should run (an adapter, or FX_REQUIRE_GPU=1 which makes
/// its absence fail).
fn gpu() -> bool {
    common::engine().is_some()
}

fn small_png(dir: &Path) -> PathBuf {
    let p = dir.join("in.png");
    let img = common::pattern_u8(48, 32);
    fxgraph::io::save_image(&p, img.width, img.height, &img.pixels, &Default::default()).unwrap();
    p
}

#[test]
fn check_accepts_the_seed_glow() {
    let o = fxrun(&["effects/glow.fx", "--check"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
    let o = fxrun(&["glow", "--check"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

#[test]
fn check_rejects_a_bad_script_with_exit_1_and_all_errors() {
    let o = fxrun(&["tests/diagnostics/unknown_pass.fx", "--check"]);
    assert_eq!(code(&o), 1);
    let e = stderr(&o);
    assert!(
        e.contains("tests/diagnostics/unknown_pass.fx:4:43: error: unknown pass `brightPas`"),
        "{e}"
    );
    assert!(
        e.contains("tests/diagnostics/unknown_pass.fx:6:11: error: unknown pass `blurY`"),
        "{e}"
    );
    assert!(e.contains("2 errors, 0 warnings"), "{e}");
}

#[test]
fn check_passes_with_warnings_only() {
    let o = fxrun(&["tests/diagnostics/culled.fx", "--check"]);
    assert_eq!(code(&o), 0);
    assert!(stderr(&o).contains("warning: pass `e/forgotten` never reaches `OUT`"));
}

#[test]
fn plan_json_has_the_documented_keys() {
    let o = fxrun(&["glow", "--plan", "--size", "1920x1080", "--json"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    assert_eq!(
        v["passes"],
        serde_json::json!(["glow/brightPass", "glow/blurX", "glow/blurY", "glow/final"])
    );
    let full = 1920u64 * 1080 * 8;
    let half = 960u64 * 540 * 8;
    assert_eq!(v["naive_bytes"], full + 2 * half);
    assert_eq!(v["peak_bytes"], full + half);
    assert_eq!(v["lower_bound_bytes"], full + half);
    let o = fxrun(&["glow", "--plan", "--size", "640x480"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("alloc  v0")
            && text.contains("run    glow/blurX")
            && text.contains("lower bound bytes"),
        "{text}"
    );
    let o = fxrun(&["glow", "--plan", "--size", "64by64"]);
    assert_eq!(code(&o), 1);
}

#[test]
fn dot_draws_passes_with_sizes_and_dashed_feedback() {
    let o = fxrun(&["glow", "--dot", "-", "--size", "100x50"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.starts_with("digraph fxgraph {"));
    assert!(
        text.contains("glow/blurX\\nSHADER.blurX\\n50x25 rgba16f linear"),
        "{text}"
    );
    let dir = tempfile::tempdir().unwrap();
    let fx = dir.path().join("fb.fx");
    std::fs::write(
        &fx,
        "EFFECT.fb = { PASS = { a = SHADER.s { img = IN  prev = PASS.a[-1] } } OUT = a }",
    )
    .unwrap();
    let o = fxrun(&[fx.to_str().unwrap(), "--dot", "-"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("style=dashed"));
}

#[test]
fn list_and_describe() {
    let o = fxrun(&["--list"]);
    assert_eq!(code(&o), 0);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.lines().any(|l| l.starts_with("glow")), "{text}");
    let o = fxrun(&["glow", "--describe"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("glow/brightPass") && text.contains("SHADER.brightPass"),
        "{text}"
    );
}

#[test]
fn describe_and_list_show_pass_parameters() {
    // The seed glow has no effect parameters: its settings are the pass
    // parameters, described by the shaders' field annotations.
    let o = fxrun(&["glow", "--describe"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let line = |key: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(key))
            .unwrap_or_else(|| panic!("no `{key}` line in\n{text}"))
            .to_string()
    };
    let sigma = line("blurX.sigma ");
    assert!(
        sigma.contains("f32")
            && sigma.contains("(default 4)")
            && sigma.contains("range [0.1, 256]")
            && sigma.contains("standard deviation"),
        "{sigma}"
    );
    for key in [
        "brightPass.threshold ",
        "brightPass.knee ",
        "blurY.sigma ",
        "final.intensity ",
    ] {
        assert!(line(key).contains("(default "), "{key}");
    }
    assert!(
        text.contains("pass parameters (--set PASS.NAME=VALUE):"),
        "{text}"
    );
    // Standard values are not parameters.
    assert!(!text.contains("out_texel"), "{text}");
    // `--set` shows in the current value.
    let o = fxrun(&["glow", "--describe", "--set", "blurX.sigma=8"]);
    let text = String::from_utf8_lossy(&o.stdout);
    let sigma = text.lines().find(|l| l.contains("blurX.sigma")).unwrap();
    assert!(
        sigma.contains("= 8") && sigma.contains("(default 4)"),
        "{sigma}"
    );
    // A pass parameter named like an effect parameter is shown by its full path
    // (`--set vignette.strength` sets the effect parameter).
    let o = fxrun(&["vignette", "--describe"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("  vignette/vignette.strength "), "{text}");
    // --list: the names, short.
    let o = fxrun(&["--list"]);
    let text = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("glow ")).unwrap();
    assert!(
        lines[at + 1].contains("pass parameters: brightPass.threshold brightPass.knee blurX.sigma blurY.sigma final.intensity"),
        "{text}"
    );
}

#[test]
fn bad_arguments_are_rejected_with_exit_1() {
    assert_eq!(code(&fxrun(&["--no-such-flag"])), 1);
    assert_eq!(code(&fxrun(&[])), 1);
    assert_eq!(code(&fxrun(&["glow"])), 1, "no input/output");
    let o = fxrun(&["no_such_effect", "--check"]);
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("no effect file or built-in effect named `no_such_effect`"));
    assert_eq!(code(&fxrun(&["--help"])), 0);
}

#[test]
fn set_errors_point_into_the_argument() {
    let o = fxrun(&["tests/diagnostics/nested_params.fx", "--check"]);
    assert_eq!(code(&o), 1);
    let dir = tempfile::tempdir().unwrap();
    let fx = dir.path().join("p.fx");
    std::fs::write(&fx, "EFFECT.p = { PARAM = { sigma = FLOAT { DEFAULT = 2  RANGE = (0.1, 64) } } PASS = { a = SHADER.s { img = IN  s = PARAM.sigma } } OUT = a }").unwrap();
    std::fs::write(
        dir.path().join("s.wgsl"),
        "@group(0) @binding(0) var img: texture_2d<f32>;
struct P { s: f32 }
@group(0) @binding(1) var<uniform> p: P;
@fragment fn fs_main(@builtin(position) q: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(img, vec2<i32>(q.xy), 0) * p.s;
}
",
    )
    .unwrap();
    let f = fx.to_str().unwrap();
    let o = fxrun(&[f, "--check", "--set", "sigma=100"]);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("--set:1:7: error: value 100 of `sigma` is out of range [0.1, 64]"),
        "{}",
        stderr(&o)
    );
    let o = fxrun(&[f, "--check", "--set", "sigmaa=3"]);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("error: `--set sigmaa`: no effect or pass parameter of that name"),
        "{}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("did you mean `sigma`?"),
        "{}",
        stderr(&o)
    );
    let o = fxrun(&[f, "--check", "--set", "sigma=(1,"]);
    assert_eq!(code(&o), 1);
    assert!(
        stderr(&o).contains("--set:1:10: error: syntax error"),
        "{}",
        stderr(&o)
    );
    let o = fxrun(&[f, "--check", "--set", "sigma=3"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

#[test]
fn applies_glow_to_an_image() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = small_png(dir.path());
    let out = dir.path().join("out.png");
    let json = dir.path().join("t.json");
    let o = fxrun(&[
        "glow",
        "-i",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--timings",
        "--timings-json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let img = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((img.width, img.height), (48, 32));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("glow/blurX") && stdout.contains("total"),
        "{stdout}"
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(t["passes"].as_array().unwrap().len(), 4);
    assert!(t["wall_ms"].as_f64().unwrap() > 0.0);
    assert_eq!(t["job"], "image");
    // No temporary files are left beside the output.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.contains("fxtmp")), "{names:?}");
}

#[test]
fn a_failed_run_leaves_the_existing_output_untouched() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = small_png(dir.path());
    let out = dir.path().join("out.png");
    std::fs::write(&out, b"precious").unwrap();
    // A shader error (exit 1), a missing input (exit 2), a corrupt input (exit 1).
    let o = fxrun(&[
        "tests/shader_errors/bindings.fx",
        "-i",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let o = fxrun(&[
        "glow",
        "-i",
        "no/such/file.png",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("no/such/file.png"), "{}", stderr(&o));
    let corrupt = dir.path().join("corrupt.png");
    let bytes = std::fs::read(&input).unwrap();
    std::fs::write(&corrupt, &bytes[..bytes.len() / 2]).unwrap();
    let o = fxrun(&[
        "glow",
        "-i",
        corrupt.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("corrupt.png"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.contains("fxtmp")), "{names:?}");
}

#[test]
fn truncated_exr_and_unknown_output_type_are_rejected() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("t.exr");
    let img = common::image_f32(16, 8, |x, _| [x as f32 * 10.0, 1.0, 0.5, 1.0]);
    fxgraph::io::save_image(&exr, 16, 8, &img.pixels, &Default::default()).unwrap();
    let bytes = std::fs::read(&exr).unwrap();
    std::fs::write(&exr, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let out = dir.path().join("o.exr");
    let o = fxrun(&[
        "glow",
        "-i",
        exr.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(!out.exists());
    let input = small_png(dir.path());
    let o = fxrun(&[
        "glow",
        "-i",
        input.to_str().unwrap(),
        "-o",
        dir.path().join("o.xyz").to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let o = fxrun(&[
        "glow",
        "-i",
        input.to_str().unwrap(),
        "-o",
        dir.path().join("o.jpg").to_str().unwrap(),
        "--bit-depth",
        "16",
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
}

#[test]
fn hdr_values_survive_an_exr_round_trip_through_an_identity_chain() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("hdr.exr");
    let img = common::image_f32(9, 5, |x, y| [x as f32 * 50.0, y as f32 * 0.25, 413.0, 1.0]);
    fxgraph::io::save_image(&exr, 9, 5, &img.pixels, &Default::default()).unwrap();
    let id = dir.path().join("id.fx");
    std::fs::write(&id, "EFFECT.id = { OUT = IN }").unwrap();
    let out = dir.path().join("out.exr");
    let o = fxrun(&[
        id.to_str().unwrap(),
        "-i",
        exr.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let back = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    let (a, b) = (common::linear(&img.pixels), common::linear(&back.pixels));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= x.abs() * 1e-3 + 1e-3, "{x} vs {y}");
    }
    assert!(b.contains(&413.0));
}

/// Shader diagnostics: rendered text equals the snapshot (`tests/shader_errors/NAME.expected`).
#[test]
fn shader_diagnostics_match_their_snapshots() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = small_png(dir.path());
    let out = dir.path().join("o.png");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bless = std::env::var("FX_BLESS").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for case in ["bindings", "wgsl_syntax", "wgsl_types", "missing_shader"] {
        let fx = format!("tests/shader_errors/{case}.fx");
        // Running it and checking it (no GPU needed) report the same diagnostics.
        let run = fxrun(&[
            &fx,
            "-i",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code(&run), 1, "{case}: {}", stderr(&run));
        let o = fxrun(&[&fx, "--check"]);
        assert_eq!(code(&o), 1, "{case}: {}", stderr(&o));
        assert_eq!(stderr(&o), stderr(&run), "{case}: --check and a run differ");
        let actual = stderr(&o);
        let expected_path = root.join(format!("tests/shader_errors/{case}.expected"));
        if bless {
            std::fs::write(&expected_path, &actual).unwrap();
            continue;
        }
        match std::fs::read_to_string(&expected_path) {
            Ok(e) if e == actual => {}
            _ => {
                std::fs::write(expected_path.with_extension("actual"), &actual).unwrap();
                failures.push(format!(
                    "{case}: differs from {} (see .actual)",
                    expected_path.display()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A final pass that writes sRGB-encoded values (OUT.COLORSPACE = srgb) is not
/// encoded a second time into an 8-bit file, and is decoded for a float file.
#[test]
fn srgb_labelled_output_is_encoded_once() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("half.wgsl"),
        "@group(0) @binding(0) var img: texture_2d<f32>;
@fragment fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(0.5, 0.5, textureLoad(img, vec2<i32>(pos.xy), 0).b * 0.0 + 0.5, 1.0);
}
",
    )
    .unwrap();
    let fx = dir.path().join("enc.fx");
    std::fs::write(&fx, "EFFECT.enc = { PASS = { a = SHADER.half { img = IN  OUT.FORMAT = rgba8  OUT.COLORSPACE = srgb } } OUT = a }").unwrap();
    let img = common::pattern_u8(6, 4);
    let f = fx.to_str().unwrap();
    let (_, _, px) = common::run(
        &mut engine,
        &[f],
        &[],
        &img,
        fxgraph::script::types::Format::Rgba8Srgb,
    )
    .unwrap();
    let fxgraph::io::Pixels::U8(v) = px else {
        panic!()
    };
    assert_eq!(
        &v[..4],
        &[128, 128, 128, 255],
        "encoded values are stored as they are"
    );
    let (_, _, px) = common::run(
        &mut engine,
        &[f],
        &[],
        &img,
        fxgraph::script::types::Format::Rgba32f,
    )
    .unwrap();
    let lin = common::linear(&px);
    assert!(
        (lin[0] - common::srgb_to_linear(0.5)).abs() < 2e-3,
        "{}",
        lin[0]
    );
}

#[test]
fn analysis_modes_know_the_aux_images_given() {
    let o = fxrun(&["chroma_composite", "--check", "--aux", "background=x.png"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = fxrun(&["chroma_composite", "--check"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("auxiliary input `AUX.background` is not provided"),
        "{}",
        stderr(&o)
    );
}

/// A still image is a one-frame sequence: temporal effects run on it.
#[test]
fn temporal_effects_run_on_a_still_image() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = small_png(dir.path());
    for effect in ["deinterlace", "frame_blend", "temporal_denoise"] {
        let out = dir.path().join(format!("{effect}.png"));
        let o = fxrun(&[
            effect,
            "-i",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code(&o), 0, "{effect}: {}", stderr(&o));
        assert!(out.exists());
    }
}

#[test]
fn renders_the_built_in_scene_through_the_default_chain() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("scene.png");
    let gb = dir.path().join("gbuffer");
    let o = fxrun(&[
        "-o",
        out.to_str().unwrap(),
        "--size",
        "96x54",
        "--gbuffer",
        gb.to_str().unwrap(),
        "--lights",
        "16",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let img = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((img.width, img.height), (96, 54));
    let v = common::linear(&img.pixels);
    let mean: f32 = v.iter().sum::<f32>() / v.len() as f32;
    assert!(
        mean > 0.05 && mean < 0.95,
        "a lit, not blank, image: mean {mean}"
    );
    for f in ["depth.png", "normal.png", "albedo.png", "scene.exr"] {
        assert!(gb.join(f).exists(), "missing G-buffer image {f}");
    }
    // Each technique renders.
    for r in ["forward", "light-prepass"] {
        let o = fxrun(&[
            "fog",
            "--scene",
            "builtin:room",
            "--renderer",
            r,
            "--size",
            "48x27",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code(&o), 0, "{r}: {}", stderr(&o));
    }
    assert_eq!(
        code(&fxrun(&[
            "--scene",
            "builtin:room",
            "--renderer",
            "raytraced",
            "-o",
            out.to_str().unwrap()
        ])),
        1
    );
}

#[test]
fn malformed_gltf_is_rejected_with_exit_1() {
    if !gpu() {
        return;
    }
    let broken = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/gltf/broken");
    let Ok(entries) = std::fs::read_dir(&broken) else {
        eprintln!("skipping: {} is absent", broken.display());
        return;
    };
    // Each broken model is in a folder of its own.
    let file = entries
        .map(|e| e.unwrap().path())
        .filter(|d| d.is_dir())
        .flat_map(|d| std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()))
        .find(|p| {
            p.extension().is_some_and(|e| e == "gltf")
                && p.to_string_lossy().contains("IndexOutOfRange")
        })
        .expect("a broken .gltf");
    let dir = tempfile::tempdir().unwrap();
    let o = fxrun(&[
        "--scene",
        file.to_str().unwrap(),
        "-o",
        dir.path().join("o.png").to_str().unwrap(),
        "--size",
        "32x32",
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}

#[test]
fn describe_every_builtin_effect() {
    // Issue 10: `--describe` works for every shipped effect without an input
    // (chroma_composite reads `--aux background=FILE`), and every effect
    // parameter and pass parameter carries a description.
    let o = fxrun(&["--list"]);
    assert_eq!(code(&o), 0);
    let list = String::from_utf8_lossy(&o.stdout).into_owned();
    let names: Vec<&str> = list
        .lines()
        .filter(|l| !l.starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.len() >= 20, "{list}");
    for name in names {
        let o = fxrun(&[name, "--describe"]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert_eq!(
            code(&o),
            0,
            "{name} --describe failed:\n{text}{}",
            stderr(&o)
        );
        let mut section = "";
        for line in text.lines() {
            if !line.starts_with(' ') {
                section = line;
                continue;
            }
            if section.starts_with("parameters") || section.starts_with("pass parameters") {
                // NAME TYPE = VALUE (default D) [range [a, b]] [(set by the effect)]  DESCRIPTION
                let last = line
                    .split("  ")
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .last();
                let after = last.unwrap_or("");
                let after = if after.starts_with("(default")
                    || after.starts_with("range")
                    || after.starts_with("(set by")
                    || after.starts_with('=')
                {
                    ""
                } else {
                    after
                };
                assert!(
                    !after.is_empty(),
                    "{name}: parameter without a description: {line}"
                );
            }
        }
    }
}

#[test]
fn huge_counts_are_rejected_with_exit_1() {
    for (arg, value) in [
        ("--queue", "18446744073709551615"),
        ("--queue", "65"),
        ("--lights", "18446744073709551615"),
        ("--lights", "100001"),
        ("--warmup", "18446744073709551615"),
    ] {
        let o = fxrun(&["tonemap", arg, value, "-i", "in.png", "-o", "out.png"]);
        assert_eq!(code(&o), 1, "{arg} {value}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(arg) && !e.contains("panicked"), "{e}");
    }
}

#[test]
fn failed_writes_of_analysis_outputs_exit_2() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let to_full = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_fxrun"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(std::fs::File::create(full).unwrap())
            .output()
            .unwrap()
    };
    for args in [
        &["--list"][..],
        &["glow", "--plan"],
        &["glow", "--plan", "--json"],
        &["glow", "--dot", "-"],
        &["glow", "--describe"],
    ] {
        let o = to_full(args);
        assert_eq!(code(&o), 2, "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("No space left"), "{}", stderr(&o));
    }
    let o = fxrun(&["glow", "--dot", "/dev/full"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("/dev/full"), "{}", stderr(&o));
    if gpu() {
        let dir = tempfile::tempdir().unwrap();
        let input = small_png(dir.path());
        let out = dir.path().join("o.png");
        let o = fxrun(&[
            "tonemap",
            "-i",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--timings-json",
            "/dev/full",
        ]);
        assert_eq!(code(&o), 2, "{}", stderr(&o));
        assert!(
            stderr(&o).contains("/dev/full: No space left"),
            "{}",
            stderr(&o)
        );
    }
    // A device is written in place, never replaced by a rename.
    assert!(!full.metadata().unwrap().is_file());
}

#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    use std::io::Read as _;
    let mut child = Command::new(env!("CARGO_BIN_EXE_fxrun"))
        .args(["--list"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Read nothing: close the pipe at once, as `| head -0` would.
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "{err}");
}

#[test]
fn scene_errors_name_the_scene() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let o = fxrun(&["--scene", "builtin:nope", "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.starts_with("fxrun: error: builtin:nope: "), "{e}");
    assert!(!e.contains("error: : "), "{e}");
}

#[test]
fn truncated_jpeg_input_is_rejected_naming_the_file() {
    let bytes = std::fs::read("examples/data/rocket.jpg")
        .or_else(|_| {
            std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/rocket.jpg"))
        })
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let cut = dir.path().join("half.jpg");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let out = dir.path().join("o.png");
    let o = fxrun(&[
        "tonemap",
        "-i",
        cut.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("half.jpg: not a valid JPEG file"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

#[test]
fn devices_are_refused_as_inputs_includes_and_gltf_uris() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let t = std::time::Instant::now();
    let o = fxrun(&["tonemap", "-i", "/dev/zero", "-o", out.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("/dev/zero: not a regular file"),
        "{}",
        stderr(&o)
    );
    let o = fxrun(&["/dev/zero", "--check"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    let fx = dir.path().join("inc.fx");
    std::fs::write(&fx, "INCLUDE \"/dev/zero\"\n").unwrap();
    let o = fxrun(&[fx.to_str().unwrap(), "--check"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("absolute include paths are not allowed"),
        "{}",
        stderr(&o)
    );
    if gpu() {
        let gltf = dir.path().join("zero.gltf");
        std::fs::write(
            &gltf,
            r#"{"asset":{"version":"2.0"},"images":[{"uri":"/dev/zero"}],"buffers":[{"uri":"/dev/zero","byteLength":4}]}"#,
        )
        .unwrap();
        let o = fxrun(&[
            "--scene",
            gltf.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code(&o), 1, "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("zero.gltf: ")
                && e.contains("/dev/zero")
                && e.contains("not a regular file"),
            "{e}"
        );
    }
    assert!(t.elapsed().as_secs() < 30);
}

#[test]
fn include_is_confined_to_the_script_folder() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("a/b");
    std::fs::create_dir_all(&sub).unwrap();
    let secret = dir.path().join("secret.fx");
    std::fs::write(&secret, "SECRET-FIRST-LINE\n").unwrap();
    let check = |text: &str| {
        let fx = sub.join("x.fx");
        std::fs::write(&fx, text).unwrap();
        fxrun(&[fx.to_str().unwrap(), "--check"])
    };
    for (inc, why) in [
        ("../../secret.fx", "`..` is not allowed"),
        ("../../../../../../../etc/passwd", "`..` is not allowed"),
        (
            secret.to_str().unwrap(),
            "absolute include paths are not allowed",
        ),
    ] {
        let o = check(&format!("INCLUDE \"{inc}\"\n"));
        assert_eq!(code(&o), 1, "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(why), "{e}");
        assert!(
            !e.contains("SECRET-FIRST-LINE") && !e.contains("root:"),
            "{e}"
        );
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, sub.join("link.fx")).unwrap();
        let o = check("INCLUDE \"link.fx\"\n");
        assert_eq!(code(&o), 1, "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("outside the including file's folder"), "{e}");
        assert!(!e.contains("SECRET-FIRST-LINE"), "{e}");
    }
    // A file in the folder (and the built-in library) still works.
    std::fs::write(sub.join("lib.fx"), "").unwrap();
    let o = check("INCLUDE \"lib.fx\"\nINCLUDE \"glow.fx\"\nEFFECT.x = { PASS = { p = SHADER.copy { img = IN } } OUT = p }\n");
    assert!(!stderr(&o).contains("cannot include"), "{}", stderr(&o));
}

#[test]
fn an_image_over_the_device_limit_is_refused_before_decoding() {
    let Some(max) = common::engine().map(|e| e.ctx.device.limits().max_texture_dimension_2d) else {
        return;
    };
    if max >= 20000 {
        eprintln!("skipping: the device takes {max} pixels per side");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The header announces 20000x20000; there are no pixels to decode.
    let big = dir.path().join("big.pgm");
    std::fs::write(&big, b"P5\n20000 20000\n255\n\0\0\0\0").unwrap();
    let out = dir.path().join("o.png");
    let o = fxrun(&[
        "tonemap",
        "-i",
        big.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("big.pgm: the image is 20000x20000, larger than the GPU's limit"),
        "{e}"
    );
}

/// An image wider than every device is guaranteed to take (8192) is checked against
/// this device's own limit, which the decode waits for while the device is created
/// on its thread: accepted when the device takes it.
#[test]
fn an_image_over_the_guaranteed_limit_waits_for_the_devices_own() {
    let Some(max) = common::engine().map(|e| e.ctx.device.limits().max_texture_dimension_2d) else {
        return;
    };
    if max < 10000 {
        eprintln!("skipping: the device takes only {max} pixels per side");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let wide = dir.path().join("wide.png");
    let img = common::image_u8(10000, 2, |x, y| [(x % 251) as u8, (y * 90) as u8, 7, 255]);
    fxgraph::io::save_image(&wide, 10000, 2, &img.pixels, &Default::default()).unwrap();
    let out = dir.path().join("o.png");
    let o = fxrun(&[
        "vignette",
        "-i",
        wide.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let r = fxgraph::io::load_image(&out, &Default::default()).unwrap();
    assert_eq!((r.width, r.height), (10000, 2));
}

/// An auxiliary image of another size than the input is an input error (exit 1)
/// naming it, and nothing is written.
#[test]
fn an_auxiliary_image_of_another_size_is_refused() {
    if common::engine().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = small_png(dir.path());
    let bg = dir.path().join("bg.png");
    let img = common::pattern_u8(20, 10);
    fxgraph::io::save_image(&bg, 20, 10, &img.pixels, &Default::default()).unwrap();
    let out = dir.path().join("o.png");
    let aux = format!("background={}", bg.display());
    let o = fxrun(&[
        "chroma_composite",
        "-i",
        input.to_str().unwrap(),
        "--aux",
        &aux,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("AUX.background") && e.contains("20x10, the input is 48x32"),
        "{e}"
    );
    assert!(!out.exists());
}

#[test]
fn no_error_line_starts_with_an_empty_path() {
    for args in [
        &["glow", "--dot", ""][..],
        &["tonemap", "--aux", "depth=", "-i", "in.png", "-o", "o.png"],
        &["--scene", "", "-o", "o.png"],
        &["tonemap", "-i", "", "-o", "o.png"],
    ] {
        let o = fxrun(args);
        assert_eq!(code(&o), 1, "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(!e.contains("error: : "), "{args:?}: {e}");
    }
    let e = fxgraph::io::IoError::Decode {
        path: PathBuf::new(),
        message: "m".into(),
    };
    assert_eq!(e.to_string(), "(empty path): m");
}

#[test]
fn a_render_size_over_the_device_limit_is_an_input_error() {
    let Some(max) = common::engine().map(|e| e.ctx.device.limits().max_texture_dimension_2d) else {
        return;
    };
    let size = format!("{}x16", max + 1);
    let o = fxrun(&["--scene", "builtin:room", "--size", &size, "-o", "o.png"]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("builtin:room: the render size"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_device_as_the_materials_file_is_refused() {
    if !gpu() || !Path::new("/dev/zero").exists() {
        return;
    }
    let o = fxrun(&[
        "--scene",
        "builtin:room",
        "--materials",
        "/dev/zero",
        "-o",
        "o.png",
    ]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("/dev/zero: not a regular file"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn help_groups_every_option_under_a_heading() {
    let o = fxrun(&["--help"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let help = String::from_utf8_lossy(&o.stdout);
    for heading in [
        "Images and batches:",
        "Sequences:",
        "Scenes (deferred renderer):",
        "Analysis:",
        "Output:",
        "Common:",
    ] {
        assert!(help.contains(heading), "no `{heading}` in:\n{help}");
    }
    // No option is left in clap's default group.
    assert!(!help.contains("\nOptions:"), "{help}");
    assert_eq!(code(&fxrun(&["-V"])), 0);
}

/// A misspelt `--set`, an unknown pass and a WGSL type error come back in one
/// report (exit 1, no output written), on a run and on `--check` alike.
#[test]
fn three_mistakes_are_reported_in_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let fx = dir.path().join("mine.fx");
    std::fs::write(
        &fx,
        "EFFECT.mine = {\n    PARAM = { gain = FLOAT { DEFAULT = 1 } }\n    PASS = {\n        a = SHADER.bad { src = IN }\n        b = SHADER.bad { src = PASS.nope }\n    }\n    OUT = b\n}\n",
    )
    .unwrap();
    std::fs::create_dir(dir.path().join("shaders")).unwrap();
    std::fs::write(
        dir.path().join("shaders/bad.wgsl"),
        "@group(0) @binding(0) var src: texture_2d<f32>;\n@fragment\nfn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {\n    let c: vec3<f32> = textureLoad(src, vec2<i32>(p.xy), 0);\n    return vec4<f32>(c, 1.0);\n}\n",
    )
    .unwrap();
    let input = small_png(dir.path());
    let out = dir.path().join("out.png");
    let fx = fx.to_str().unwrap();
    for args in [
        vec![
            fx,
            "-i",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--set",
            "gian=2",
        ],
        vec![fx, "--check", "--set", "gian=2"],
    ] {
        let o = fxrun(&args);
        assert_eq!(code(&o), 1, "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("mine.fx:5:37: error: unknown pass `nope`"),
            "{e}"
        );
        assert!(
            e.contains("`--set gian`: no effect or pass parameter"),
            "{e}"
        );
        assert!(e.contains("did you mean `gain`?"), "{e}");
        assert!(
            e.contains("shaders/bad.wgsl:4:9: error: WGSL: the type of `c` is expected to be `vec3<f32>`, but got `vec4<f32>`"),
            "{e}"
        );
        assert!(e.contains("3 errors"), "{e}");
        assert!(!out.exists());
    }
    // The script and WGSL errors are both reported, and a name the
    // broken script could still mean (`a.anything`) is not invented as an error.
    let o = fxrun(&[
        fx,
        "--check",
        "--set",
        "a.anything=1",
        "--set",
        "mine.gain=2",
    ]);
    let e = stderr(&o);
    assert!(e.contains("2 errors"), "{e}");
    assert!(!e.contains("--set"), "{e}");
}
