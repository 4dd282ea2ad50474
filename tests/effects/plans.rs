//! edges, pencil, chroma_key, chroma_composite, format_convert, fxaa and glow compile
//! without warnings, plan at the memory lower bound without inserted conversion
//! passes, and are built in with a description.

use crate::oracle::plan_for;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::script::types::Format;

#[test]
fn effects_compile_without_warnings_and_plan_at_the_lower_bound() {
    for name in [
        "edges",
        "pencil",
        "chroma_key",
        "format_convert",
        "fxaa",
        "glow",
    ] {
        let path = format!("effects/{name}.fx");
        for (w, h) in [(64, 64), (67, 41), (1920, 1080)] {
            let (p, warnings, plan_warnings) = plan_for(&[&path], w, h);
            assert_eq!((warnings, plan_warnings), (0, 0), "{name}: warnings");
            assert_eq!(
                p.peak_bytes, p.lower_bound_bytes,
                "{name} {w}x{h}: peak above the lower bound"
            );
            assert_eq!(
                p.validate(),
                Ok(p.peak_bytes),
                "{name} {w}x{h}: invalid plan"
            );
            // 8-bit inputs need no inserted colour-space conversion pass.
            assert!(
                p.passes
                    .iter()
                    .all(|q| !q.path.contains(":linear") && !q.path.contains(":srgb")),
                "{name}: conversion pass in {:?}",
                p.passes
            );
        }
    }
    // chroma_composite reads AUX.background: plan it with that image provided.
    let composite = std::path::Path::new("effects/chroma_composite.fx");
    let (graph, diags, sources) = crate::common::compile::compile_file(composite);
    let graph = graph.unwrap_or_else(|| panic!("chroma_composite:\n{}", diags.render(&sources)));
    assert_eq!(diags.warning_count(), 0);
    let mut input = InputDesc::rgba8_srgb(640, 360);
    input.aux.push(("background".into(), Format::Rgba8Srgb));
    let (p, notes) = plan(&graph, &input, &PlanOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render(&sources)));
    assert_eq!(
        (notes.warning_count(), p.passes.len(), p.peak_bytes),
        (0, 1, 0)
    );
    // The built-ins are embedded and listed with their descriptions.
    let list = fxgraph::graph::library::builtin_effects();
    for name in [
        "edges",
        "pencil",
        "chroma_key",
        "chroma_composite",
        "format_convert",
        "fxaa",
    ] {
        let d = list
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} is not built in"));
        assert!(!d.1.is_empty(), "{name} has no DESCRIPTION");
    }
}
