//! The analysis modes, which need no GPU: `--check`, `--plan`, `--dot`, `--list`,
//! `--describe` and `--help`, and how their output fails.

use crate::common::cli::{
    code, command, exits, exits_with, fxrun, fxrun_line, stderr, stdout, write,
};
use std::path::Path;

#[test]
fn check_accepts_the_seed_glow() {
    let o = fxrun(&["effects/glow.fx", "--check"]);
    let e = exits(&o, 0);
    assert!(e.is_empty(), "{e}");
    exits(&fxrun(&["glow", "--check"]), 0);
}

#[test]
fn check_rejects_a_bad_script_with_exit_1_and_all_errors() {
    let o = fxrun(&["tests/diagnostics/unknown_pass.fx", "--check"]);
    exits_with(
        &o,
        1,
        &[
            "tests/diagnostics/unknown_pass.fx:4:43: error: unknown pass `brightPas`",
            "tests/diagnostics/unknown_pass.fx:6:11: error: unknown pass `blurY`",
            "2 errors, 0 warnings",
        ],
    );
}

#[test]
fn check_passes_with_warnings_only() {
    let o = fxrun(&["tests/diagnostics/culled.fx", "--check"]);
    exits_with(&o, 0, &["warning: pass `e/forgotten` never reaches `OUT`"]);
}

#[test]
fn plan_json_has_the_documented_keys() {
    let o = fxrun(&["glow", "--plan", "--size", "1920x1080", "--json"]);
    exits(&o, 0);
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
    let text = stdout(&fxrun(&["glow", "--plan", "--size", "640x480"]));
    assert!(
        text.contains("alloc  v0")
            && text.contains("run    glow/blurX")
            && text.contains("lower bound bytes"),
        "{text}"
    );
    assert_eq!(code(&fxrun(&["glow", "--plan", "--size", "64by64"])), 1);
}

#[test]
fn dot_draws_passes_with_sizes_and_dashed_feedback() {
    let o = fxrun(&["glow", "--dot", "-", "--size", "100x50"]);
    exits(&o, 0);
    let text = stdout(&o);
    assert!(text.starts_with("digraph fxgraph {"));
    assert!(
        text.contains("glow/blurX\\nSHADER.blurX\\n50x25 rgba16f linear"),
        "{text}"
    );
    let dir = tempfile::tempdir().unwrap();
    let fb = "EFFECT.fb = { PASS = { a = SHADER.s { img = IN  prev = PASS.a[-1] } } OUT = a }";
    let o = fxrun_line("{} --dot -", &[&write(dir.path(), "fb.fx", fb)]);
    assert!(stdout(&o).contains("style=dashed"));
}

#[test]
fn list_and_describe() {
    let o = fxrun(&["--list"]);
    assert_eq!(code(&o), 0);
    let text = stdout(&o);
    assert!(text.lines().any(|l| l.starts_with("glow")), "{text}");
    let text = stdout(&fxrun(&["glow", "--describe"]));
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
    exits(&o, 0);
    let text = stdout(&o);
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
    let text = stdout(&fxrun(&["glow", "--describe", "--set", "blurX.sigma=8"]));
    let sigma = text.lines().find(|l| l.contains("blurX.sigma")).unwrap();
    assert!(
        sigma.contains("= 8") && sigma.contains("(default 4)"),
        "{sigma}"
    );
    // A pass parameter named like an effect parameter is shown by its full path
    // (`--set vignette.strength` sets the effect parameter).
    let text = stdout(&fxrun(&["vignette", "--describe"]));
    assert!(text.contains("  vignette/vignette.strength "), "{text}");
    // --list: the names, short.
    let text = stdout(&fxrun(&["--list"]));
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("glow ")).unwrap();
    assert!(
        lines[at + 1].contains("pass parameters: brightPass.threshold brightPass.knee blurX.sigma blurY.sigma final.intensity"),
        "{text}"
    );
}

#[test]
fn describe_every_builtin_effect() {
    // Issue 10: `--describe` works for every shipped effect without an input
    // (chroma_composite reads `--aux background=FILE`), and every effect
    // parameter and pass parameter carries a description.
    let o = fxrun(&["--list"]);
    assert_eq!(code(&o), 0);
    let list = stdout(&o);
    let names: Vec<&str> = list
        .lines()
        .filter(|l| !l.starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.len() >= 20, "{list}");
    for name in names {
        let o = fxrun(&[name, "--describe"]);
        let text = stdout(&o);
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
fn analysis_modes_know_the_aux_images_given() {
    let o = fxrun(&["chroma_composite", "--check", "--aux", "background=x.png"]);
    exits(&o, 0);
    let o = fxrun(&["chroma_composite", "--check"]);
    exits_with(&o, 1, &["auxiliary input `AUX.background` is not provided"]);
}

#[test]
fn help_groups_every_option_under_a_heading() {
    let o = fxrun(&["--help"]);
    exits(&o, 0);
    let help = stdout(&o);
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

#[test]
fn failed_writes_of_analysis_outputs_exit_2() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let to_full = |args: &[&str]| {
        command(args)
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
    exits_with(&o, 2, &["/dev/full"]);
    if crate::gpu() {
        let dir = tempfile::tempdir().unwrap();
        let input = crate::common::cli::input_png(dir.path());
        let out = dir.path().join("o.png");
        let o =
            crate::common::cli::apply("tonemap", &input, &out, &["--timings-json", "/dev/full"]);
        exits_with(&o, 2, &["/dev/full: No space left"]);
    }
    // A device is written in place, never replaced by a rename.
    assert!(!full.metadata().unwrap().is_file());
}

#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    use std::io::Read as _;
    let mut child = command(["--list"])
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
