//! Arguments `fxrun` rejects (exit 1): unknown flags and effects, `--set` values,
//! counts out of range, empty paths, and several mistakes reported in one run.

use crate::common::cli::{
    code, exits, exits_with, fxrun, fxrun_line, input_png, write, write_effect,
};
use std::path::PathBuf;

#[test]
fn bad_arguments_are_rejected_with_exit_1() {
    assert_eq!(code(&fxrun(&["--no-such-flag"])), 1);
    assert_eq!(code(&fxrun(&[])), 1);
    assert_eq!(code(&fxrun(&["glow"])), 1, "no input/output");
    let o = fxrun(&["no_such_effect", "--check"]);
    exits_with(
        &o,
        1,
        &["no effect file or built-in effect named `no_such_effect`"],
    );
    assert_eq!(code(&fxrun(&["--help"])), 0);
    // --size with an input is the viewport, which glow's passes do not scale
    // from: refused, never silently ignored
    let dir = tempfile::tempdir().unwrap();
    let input = input_png(dir.path());
    let out = dir.path().join("o.png");
    let o = fxrun(&[
        "glow",
        "-i",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "64x32",
    ]);
    exits_with(&o, 1, &["--size with -i INPUT sets the viewport"]);
    assert!(!out.exists(), "nothing written");
}

/// A shader `s` with one parameter `s`, beside an effect `p` whose PARAM `sigma`
/// (range [0.1, 64]) sets it.
const SIGMA_FX: &str = "EFFECT.p = { PARAM = { sigma = FLOAT { DEFAULT = 2  RANGE = (0.1, 64) } } PASS = { a = SHADER.s { img = IN  s = PARAM.sigma } } OUT = a }";
const SIGMA_WGSL: &str = "@group(0) @binding(0) var img: texture_2d<f32>;
struct P { s: f32 }
@group(0) @binding(1) var<uniform> p: P;
@fragment fn fs_main(@builtin(position) q: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(img, vec2<i32>(q.xy), 0) * p.s;
}
";

#[test]
fn set_errors_point_into_the_argument() {
    let o = fxrun(&["tests/diagnostics/nested_params.fx", "--check"]);
    assert_eq!(code(&o), 1);
    let dir = tempfile::tempdir().unwrap();
    let f = &write_effect(dir.path(), "p", SIGMA_FX, ("s", SIGMA_WGSL));
    let o = fxrun(&[f, "--check", "--set", "sigma=100"]);
    exits_with(
        &o,
        1,
        &["--set:1:7: error: value 100 of `sigma` is out of range [0.1, 64]"],
    );
    let o = fxrun(&[f, "--check", "--set", "sigmaa=3"]);
    exits_with(
        &o,
        1,
        &[
            "error: `--set sigmaa`: no effect or pass parameter of that name",
            "did you mean `sigma`?",
        ],
    );
    let o = fxrun(&[f, "--check", "--set", "sigma=(1,"]);
    exits_with(&o, 1, &["--set:1:10: error: syntax error"]);
    exits(&fxrun(&[f, "--check", "--set", "sigma=3"]), 0);
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
        let e = crate::common::cli::stderr(&o);
        assert_eq!(code(&o), 1, "{arg} {value}: {e}");
        assert!(e.contains(arg) && !e.contains("panicked"), "{e}");
    }
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
        let e = crate::common::cli::stderr(&o);
        assert_eq!(code(&o), 1, "{args:?}: {e}");
        assert!(!e.contains("error: : "), "{args:?}: {e}");
    }
    let e = fxgraph::io::IoError::Decode {
        path: PathBuf::new(),
        message: "m".into(),
    };
    assert_eq!(e.to_string(), "(empty path): m");
}

/// An effect with a parameter `gain` whose second pass reads an unknown pass.
const MINE_FX: &str = "EFFECT.mine = {\n    PARAM = { gain = FLOAT { DEFAULT = 1 } }\n    PASS = {\n        a = SHADER.bad { src = IN }\n        b = SHADER.bad { src = PASS.nope }\n    }\n    OUT = b\n}\n";
/// A shader with a type error on line 4.
const BAD_WGSL: &str = "@group(0) @binding(0) var src: texture_2d<f32>;\n@fragment\nfn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {\n    let c: vec3<f32> = textureLoad(src, vec2<i32>(p.xy), 0);\n    return vec4<f32>(c, 1.0);\n}\n";

/// A misspelt `--set`, an unknown pass and a WGSL type error come back in one
/// report (exit 1, no output written), on a run and on `--check` alike.
#[test]
fn three_mistakes_are_reported_in_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let fx = write(dir.path(), "mine.fx", MINE_FX);
    std::fs::create_dir(dir.path().join("shaders")).unwrap();
    write(dir.path(), "shaders/bad.wgsl", BAD_WGSL);
    let input = input_png(dir.path());
    let out = dir.path().join("out.png");
    for o in [
        fxrun_line("{} -i {} -o {} --set gian=2", &[&fx, &input, &out]),
        fxrun_line("{} --check --set gian=2", &[&fx]),
    ] {
        exits_with(
            &o,
            1,
            &[
                "mine.fx:5:37: error: unknown pass `nope`",
                "`--set gian`: no effect or pass parameter",
                "did you mean `gain`?",
                "shaders/bad.wgsl:4:9: error: WGSL: the type of `c` is expected to be `vec3<f32>`, but got `vec4<f32>`",
                "3 errors",
            ],
        );
        assert!(!out.exists());
    }
    // The script and WGSL errors are both reported, and a name the
    // broken script could still mean (`a.anything`) is not invented as an error.
    let o = fxrun_line("{} --check --set a.anything=1 --set mine.gain=2", &[&fx]);
    let e = crate::common::cli::stderr(&o);
    assert!(e.contains("2 errors"), "{e}");
    assert!(!e.contains("--set"), "{e}");
}
