//! Snapshot tests of every diagnostic kind: each `tests/diagnostics/NAME.fx` is
//! compiled (and planned for a 1920x1080 input with the G-buffer, except
//! `aux_missing.fx`, planned without it) and the rendered diagnostics must equal
//! `NAME.expected` exactly. A missing or different snapshot fails and writes
//! `NAME.actual` next to it; `FX_BLESS=1` writes `NAME.expected` (review the diff).

use crate::common;

use common::compile::compile_file;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use std::path::Path;

fn render(rel: &str) -> String {
    let (graph, mut diags, sources) = compile_file(Path::new(rel));
    if let Some(g) = graph {
        let mut input = InputDesc::rgba8_srgb(1920, 1080);
        if !rel.ends_with("aux_missing.fx") {
            input = input.with_aux(&fxgraph::render::published_aux(true));
        }
        match plan(&g, &input, &PlanOptions::default()) {
            Ok((_, notes)) => diags.extend(notes),
            Err(d) => diags.extend(d),
        }
    }
    diags.render(&sources)
}

#[test]
fn diagnostics_match_their_snapshots() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(root).unwrap();
    let mut cases: Vec<_> = std::fs::read_dir(root.join("tests/diagnostics"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fx"))
        .collect();
    cases.sort();
    assert!(cases.len() >= 18, "diagnostic cases missing");
    let bless = std::env::var("FX_BLESS").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for case in cases {
        let rel = format!(
            "tests/diagnostics/{}",
            case.file_name().unwrap().to_str().unwrap()
        );
        let actual = render(&rel);
        assert!(!actual.trim().is_empty(), "{rel}: produced no diagnostic");
        let expected_path = case.with_extension("expected");
        let actual_path = case.with_extension("actual");
        if bless {
            std::fs::write(&expected_path, &actual).unwrap();
            continue;
        }
        match std::fs::read_to_string(&expected_path) {
            Ok(expected) if expected == actual => {
                let _ = std::fs::remove_file(&actual_path);
            }
            Ok(_) => {
                std::fs::write(&actual_path, &actual).unwrap();
                failures.push(format!(
                    "{rel}: differs from its snapshot (see {})",
                    actual_path.display()
                ));
            }
            Err(_) => {
                std::fs::write(&actual_path, &actual).unwrap();
                failures.push(format!(
                    "{rel}: no snapshot {} (actual output written to {})",
                    expected_path.display(),
                    actual_path.display()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A cycle names every pass of the cycle, each with its span.
#[test]
fn a_cycle_is_reported_whole() {
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let text = render("tests/diagnostics/cycle.fx");
    assert!(
        text.contains("dependency cycle: loop/a → loop/b → loop/c → loop/a"),
        "{text}"
    );
    for reader in [
        "`loop/a` reads `loop/c`",
        "`loop/b` reads `loop/a`",
        "`loop/c` reads `loop/b`",
    ] {
        assert!(text.contains(reader), "{reader} missing in\n{text}");
    }
    assert!(
        !text.contains("loop/d →"),
        "d is not part of the cycle:\n{text}"
    );
}
