//! Every ```fx example in docs/language.md compiles without errors or warnings and
//! plans at 256x256 (with the G-buffer as auxiliary inputs).

use crate::common;

use common::compile::compile_file;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};

fn examples() -> Vec<(usize, String)> {
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/language.md")).unwrap();
    let mut out = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (i, line) in doc.lines().enumerate() {
        match &mut current {
            None if line.trim() == "```fx" => current = Some((i + 1, String::new())),
            Some(_) if line.trim() == "```" => out.push(current.take().unwrap()),
            Some((_, text)) => {
                text.push_str(line);
                text.push('\n');
            }
            None => {}
        }
    }
    out
}

#[test]
fn every_documented_example_compiles_and_plans() {
    let examples = examples();
    assert!(
        examples.len() >= 12,
        "expected the documented constructs, found {} examples",
        examples.len()
    );
    let dir = tempfile::tempdir().unwrap();
    for (line, text) in examples {
        let path = dir.path().join(format!("example_{line}.fx"));
        std::fs::write(&path, &text).unwrap();
        let (graph, diags, sources) = compile_file(&path);
        assert!(
            diags.is_empty(),
            "docs/language.md:{line}: example has diagnostics:\n{}",
            diags.render(&sources)
        );
        let graph = graph.unwrap_or_else(|| panic!("docs/language.md:{line}: no graph"));
        let input = InputDesc::rgba8_srgb(256, 256).with_aux(&fxgraph::render::published_aux(true));
        let (p, notes) = plan(&graph, &input, &PlanOptions::default()).unwrap_or_else(|d| {
            panic!(
                "docs/language.md:{line}: plan failed:\n{}",
                d.render(&sources)
            )
        });
        p.validate()
            .unwrap_or_else(|e| panic!("docs/language.md:{line}: invalid plan: {e}"));
        assert_eq!(p.peak_bytes, p.lower_bound_bytes, "docs/language.md:{line}");
        // The colour-space example must say what it converts.
        // In the colour-space example every input is read in the space its
        // producer wrote: no conversion pass, no reinterpreted view, no note.
        // (Conversions are tested in tests/graph.rs.)
        if text.contains("img.COLORSPACE = srgb") {
            use fxgraph::graph::plan::{PassShader, View};
            assert!(notes.list.is_empty(), "{}", notes.render(&sources));
            assert!(p
                .passes
                .iter()
                .all(|q| !matches!(q.shader, PassShader::Convert { .. })));
            assert!(p
                .passes
                .iter()
                .flat_map(|q| &q.inputs)
                .all(|i| i.view == View::Natural));
        }
    }
}

/// Every construct the document describes appears in an example.
#[test]
fn examples_cover_the_constructs() {
    let all: String = examples().into_iter().map(|(_, t)| t).collect();
    for construct in [
        "EFFECT.",
        "PASS = {",
        "SHADER.",
        "OUT = ",
        "IN[-1]",
        "IN[+1]",
        "[-1]",
        "AUX.depth",
        "OUT.SIZE",
        "OUT.SCALE = (",
        "OUT.SCALE = 0.5",
        "OUT.RELATIVE_TO",
        "OUT.FORMAT",
        "OUT.COLORSPACE",
        "img.COLORSPACE",
        "FORMAT = rgba16f",
        ".FILTER = nearest",
        ".WRAP = (repeat, mirror)",
        "PARAM = {",
        "FLOAT {",
        "INT {",
        "BOOL {",
        "VEC3 {",
        "ENUM {",
        "VALUES",
        "RANGE",
        "DESCRIPTION",
        "PARAM.",
        "DEFINE.",
        "= EFFECT.",
        "INCLUDE",
        "//",
        "/*",
        "true",
        "(1, 0.5, 0.2)",
        "JITTER = halton23",
    ] {
        assert!(
            all.contains(construct),
            "no example in docs/language.md uses `{construct}`"
        );
    }
}
