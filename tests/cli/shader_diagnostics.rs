//! Shader diagnostics of `fxrun`: the rendered text of each broken effect in
//! tests/shader_errors/ equals its snapshot (`NAME.expected`; `FX_BLESS=1` rewrites
//! the snapshots), on a run and on `--check` alike.

use crate::common::cli::{apply, code, fxrun, input_png, stderr};
use crate::common::gpu_scratch;
use std::path::Path;

#[test]
fn shader_diagnostics_match_their_snapshots() {
    let Some(dir) = gpu_scratch() else { return };
    let input = input_png(dir.path());
    let out = dir.path().join("o.png");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bless = std::env::var("FX_BLESS").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for case in [
        "bindings",
        "wgsl_syntax",
        "wgsl_types",
        "wgsl_struct_types",
        "missing_shader",
    ] {
        let fx = format!("tests/shader_errors/{case}.fx");
        // Running it and checking it (no GPU needed) report the same diagnostics.
        let run = apply(&fx, &input, &out, &[]);
        assert_eq!(code(&run), 1, "{case}: {}", stderr(&run));
        let o = fxrun(&[&fx, "--check"]);
        assert_eq!(code(&o), 1, "{case}: {}", stderr(&o));
        assert_eq!(stderr(&o), stderr(&run), "{case}: --check and a run differ");
        let actual = stderr(&o);
        // WGSL type names only, never naga's `Debug` forms of types
        for dump in [
            "Struct {",
            "StructMember",
            "Scalar {",
            "Vector {",
            "Array {",
        ] {
            assert!(!actual.contains(dump), "{case}: `{dump}` in\n{actual}");
        }
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
