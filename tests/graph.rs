//! Graph compiler and lifetime plan: schedule, culling, namespaces, temporal
//! references, chains, and property tests of the plan on random DAGs.

use crate::common;

use common::compile::{compile_chain, compile_file};
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions, Resource, ReusePolicy, Step};
use fxgraph::graph::{compile, library, CompileRequest, Graph};
use fxgraph::script::{Diagnostics, SourceMap};
use proptest::prelude::*;
use std::path::PathBuf;

const SEED_GLOW: &str = "EFFECT.glow = {
    PASS = {
        brightPass = SHADER.brightPass {
            img = IN
        }
        blurX = SHADER.blurX {
            img = PASS.brightPass
            OUT.SCALE = (0.5, 0.5)
        }
        blurY = SHADER.blurY {
            img = PASS.blurX
            OUT.SCALE = (0.5, 0.5)
        }
        final = SHADER.add {
            img1 = IN
            img2 = PASS.blurY
        }
    }
    OUT = final
}
";

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// [`compile_chain`], which must give a graph without any diagnostic.
fn clean(effects: &[String], sets: &[&str]) -> Graph {
    let (g, d, s) = compile_chain(effects, sets);
    assert!(d.is_empty(), "{}", d.render(&s));
    g.unwrap()
}

/// The effect file `name` holding `text`, compiled with the `--set` arguments
/// `sets`: a graph without any diagnostic.
fn clean_file(name: &str, text: &str, sets: &[&str]) -> Graph {
    let dir = tempfile::tempdir().unwrap();
    clean(&[write(&dir, name, text).display().to_string()], sets)
}

fn compile_text(text: &str) -> (Option<Graph>, Diagnostics, SourceMap) {
    let dir = tempfile::tempdir().unwrap();
    compile_file(&write(&dir, "t.fx", text))
}

fn ok(text: &str) -> Graph {
    let (g, d, s) = compile_text(text);
    assert!(!d.has_errors(), "{}", d.render(&s));
    g.unwrap()
}

fn names(g: &Graph) -> Vec<String> {
    g.schedule.iter().map(|&n| g.pass(n).path.clone()).collect()
}

#[test]
fn shipped_glow_is_the_seed_text_byte_for_byte() {
    let shipped =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/effects/glow.fx")).unwrap();
    assert_eq!(shipped, SEED_GLOW);
    assert_eq!(library::embedded_effect("glow.fx"), Some(SEED_GLOW));
}

#[test]
fn glow_compiles_schedules_and_sizes_as_the_paper_intends() {
    let g = ok(SEED_GLOW);
    assert_eq!(
        names(&g),
        ["glow/brightPass", "glow/blurX", "glow/blurY", "glow/final"]
    );
    let (p, _) = plan(
        &g,
        &InputDesc::rgba8_srgb(1920, 1080),
        &PlanOptions::default(),
    )
    .unwrap();
    let sizes: Vec<(u32, u32)> = p
        .passes
        .iter()
        .map(|p| (p.desc.width, p.desc.height))
        .collect();
    // Both blurs are half of IN (each scale is relative to the effect input).
    assert_eq!(sizes, [(1920, 1080), (960, 540), (960, 540), (1920, 1080)]);
    assert_eq!(p.passes[3].output, Resource::Output);
    p.validate().unwrap();
    // brightPass (rgba16f, 8 B/px) and blurX are live together at the peak.
    let full = 1920 * 1080 * 8u64;
    let half = 960 * 540 * 8u64;
    assert_eq!(p.lower_bound_bytes, full + half);
    assert_eq!(p.peak_bytes, p.lower_bound_bytes);
    assert_eq!(p.naive_bytes, full + 2 * half);
}

/// `OUT.RELATIVE_TO = (X, Y)`: the width scales input `X`'s, the height `Y`'s
/// (`IN`: the effect input); a name that is not an input is an error.
#[test]
fn relative_to_may_name_one_image_per_axis() {
    let g = ok("EFFECT.axes = { PASS = {
            a = SHADER.s { img = IN  OUT.SIZE = (10, 20) }
            b = SHADER.s { img = PASS.a  OUT.SCALE = (2, 3)  OUT.RELATIVE_TO = (img, IN) }
            c = SHADER.s { img = PASS.b  OUT.SCALE = 0.5  OUT.RELATIVE_TO = (IN, img) }
        } OUT = c }");
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(64, 48), &PlanOptions::default()).unwrap();
    let sizes: Vec<(u32, u32)> = p
        .passes
        .iter()
        .map(|p| (p.desc.width, p.desc.height))
        .collect();
    // b: 2 x a's width 10, 3 x IN's height 48; c: half IN's width, half b's height
    assert_eq!(sizes, [(10, 20), (20, 144), (32, 72)]);
    let (_, d, s) = compile_text(
        "EFFECT.bad = { PASS = {
            a = SHADER.s { img = IN  OUT.SCALE = 2  OUT.RELATIVE_TO = (img, nothere) }
        } OUT = a }",
    );
    let text = d.render(&s);
    assert!(
        d.has_errors() && text.contains("`OUT.RELATIVE_TO` names `nothere`"),
        "{text}"
    );
}

/// `OUT.WIDTH` / `OUT.HEIGHT` fix one axis in pixels and leave the other
/// scaled; `VIEWPORT` is the run's output size (the input's unless the plan's
/// input says otherwise, as `fxrun --size` does for `-i INPUT`).
#[test]
fn one_axis_may_be_in_pixels_and_scale_from_the_viewport() {
    let g = ok("EFFECT.axes = { PASS = {
            a = SHADER.s { img = IN  OUT.WIDTH = 40  OUT.SCALE = (1, 0.5)  OUT.RELATIVE_TO = VIEWPORT }
            b = SHADER.s { img = PASS.a  OUT.HEIGHT = 7  OUT.SCALE = 2  OUT.RELATIVE_TO = img }
            c = SHADER.s { img = PASS.b  OUT.RELATIVE_TO = VIEWPORT }
        } OUT = c }");
    assert!(g.scales_from_viewport());
    let sizes = |desc: &InputDesc| -> Vec<(u32, u32)> {
        let (p, _) = plan(&g, desc, &PlanOptions::default()).unwrap();
        p.passes
            .iter()
            .map(|p| (p.desc.width, p.desc.height))
            .collect()
    };
    // a: 40 px by half the viewport's height; b: twice a's width by 7 px; c: the viewport.
    assert_eq!(
        sizes(&InputDesc::rgba8_srgb(64, 48)),
        [(40, 24), (80, 7), (64, 48)]
    );
    let wide = InputDesc::rgba8_srgb(64, 48).with_viewport(Some((100, 30)));
    assert_eq!(sizes(&wide), [(40, 15), (80, 7), (100, 30)]);
    assert!(
        !ok("EFFECT.e = { PASS = { a = SHADER.s { img = IN } } OUT = a }").scales_from_viewport()
    );
    for (script, needle) in [
        (
            "OUT.SIZE = (4, 4)  OUT.WIDTH = 3",
            "`OUT.SIZE` with `OUT.WIDTH` or `OUT.HEIGHT`",
        ),
        (
            "OUT.WIDTH = 3  OUT.HEIGHT = 4  OUT.SCALE = 2",
            "the scale has no axis to scale",
        ),
        (
            "OUT.WIDTH = 2.5",
            "`OUT.WIDTH` takes whole numbers of pixels",
        ),
        (
            "OUT.HEIGHT = (1, 2)",
            "`OUT.HEIGHT` expects a number of pixels",
        ),
    ] {
        let (_, d, s) = compile_text(&format!(
            "EFFECT.bad = {{ PASS = {{ a = SHADER.s {{ img = IN  {script} }} }} OUT = a }}"
        ));
        let text = d.render(&s);
        assert!(d.has_errors() && text.contains(needle), "{script}: {text}");
    }
}

/// `STEP` reaches the graph's parameter (the viewer's slider notch); it must be
/// a positive number.
#[test]
fn a_parameter_step_is_kept_and_checked() {
    let g = ok(
        "EFFECT.stepped = { PARAM = { k = FLOAT { DEFAULT = 1  RANGE = (0, 2)  STEP = 0.25 } }
        PASS = { a = SHADER.s { img = IN  k = PARAM.k } } OUT = a }",
    );
    assert_eq!(g.params[0].step, Some(0.25));
    let (_, d, s) = compile_text(
        "EFFECT.bad = { PARAM = { k = FLOAT { DEFAULT = 1  STEP = -1 } }
        PASS = { a = SHADER.s { img = IN  k = PARAM.k } } OUT = a }",
    );
    let text = d.render(&s);
    assert!(
        d.has_errors() && text.contains("a positive number"),
        "{text}"
    );
}

#[test]
fn schedule_follows_dependencies_and_breaks_ties_by_declaration() {
    let g = ok("EFFECT.e = { PASS = {
        d = SHADER.s { a = PASS.b  b = PASS.c }
        c = SHADER.s { a = IN }
        b = SHADER.s { a = IN }
        a = SHADER.s { a = IN }
        z = SHADER.s { a = PASS.d  b = PASS.a }
    } OUT = z }");
    assert_eq!(names(&g), ["e/c", "e/b", "e/d", "e/a", "e/z"]);
}

#[test]
fn unused_passes_are_culled_with_a_warning() {
    let (g, d, s) = compile_text("EFFECT.e = { PASS = { a = SHADER.s { img = IN } unused = SHADER.s { img = PASS.a } } OUT = a }");
    let g = g.unwrap();
    assert_eq!(names(&g), ["e/a"]);
    let text = d.render(&s);
    assert!(
        text.contains("warning: pass `e/unused` never reaches `OUT`; it is culled"),
        "{text}"
    );
    assert!(!d.has_errors());
}

#[test]
fn feedback_is_not_a_cycle_and_gets_a_ring() {
    let g = ok("EFFECT.acc = { PASS = { a = SHADER.s { cur = IN  prev = PASS.a[-1] } } OUT = a }");
    assert!(g.has_feedback());
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(64, 32), &PlanOptions::default()).unwrap();
    assert_eq!(p.rings.len(), 1);
    assert_eq!(p.rings[0].depth, 1);
    // The pass writes into its ring; the output gets a copy.
    assert_eq!(
        p.passes[0].output,
        Resource::Persistent { ring: 0, back: 0 }
    );
    assert_eq!(
        p.passes[0].inputs[1].resource,
        Resource::Persistent { ring: 0, back: 1 }
    );
    assert_eq!(p.passes.last().unwrap().output, Resource::Output);
    assert_eq!(p.persistent_bytes, 2 * 64 * 32 * 8);
    p.validate().unwrap();
}

#[test]
fn temporal_inputs_set_latency_and_history() {
    let g = ok("EFFECT.t = { PASS = { a = SHADER.s { p = IN[-2]  c = IN  n = IN[+1] } } OUT = a }");
    assert_eq!((g.history, g.latency), (2, 1));
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(10, 10), &PlanOptions::default()).unwrap();
    assert_eq!(p.persistent_bytes, 3 * 10 * 10 * 4);
}

#[test]
fn nested_effects_expand_in_their_namespace_with_their_parameters() {
    let g = clean_file(
        "outer.fx",
        "EFFECT.inner = {
            PARAM = { k = FLOAT { DEFAULT = 1  RANGE = (0, 10) } }
            PASS = { x = SHADER.s { img = IN  k = PARAM.k  OUT.SCALE = 0.5 } }
            OUT = x
        }
        EFFECT.outer = {
            PARAM = { strength = FLOAT { DEFAULT = 3  RANGE = (0, 10) } }
            PASS = {
                a = EFFECT.inner { IN = IN  k = 2 }
                b = EFFECT.inner { IN = PASS.a  k = PARAM.strength }
                c = SHADER.s { img = PASS.b  prev = PASS.b[-1] }
            }
            OUT = c
        }",
        &["strength=7"],
    );
    assert_eq!(names(&g), ["outer/a/x", "outer/b/x", "outer/c"]);
    let k: Vec<f64> = g.schedule[..2]
        .iter()
        .map(|&n| g.pass(n).params[0].value[0])
        .collect();
    assert_eq!(k, [2.0, 7.0]);
    let (pl, _) = plan(&g, &InputDesc::rgba8_srgb(100, 60), &PlanOptions::default()).unwrap();
    // inner's scale is relative to its own IN: 100 -> 50 -> 25.
    assert_eq!(
        (
            pl.passes[0].desc.width,
            pl.passes[1].desc.width,
            pl.passes[2].desc.width
        ),
        (50, 25, 100)
    );
}

#[test]
fn chains_share_one_graph_and_namespace_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let a = write(
        &dir,
        "a.fx",
        "EFFECT.a = { PASS = { p = SHADER.s { img = IN } } OUT = p }",
    );
    let a = a.display().to_string();
    let g = clean(&[a.clone(), "glow".into(), a], &[]);
    assert_eq!(
        names(&g),
        [
            "a/p",
            "glow/brightPass",
            "glow/blurX",
            "glow/blurY",
            "glow/final",
            "a#2/p"
        ]
    );
}

#[test]
fn output_may_be_the_input() {
    let g = ok("EFFECT.id = { OUT = IN }");
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(8, 8), &PlanOptions::default()).unwrap();
    assert_eq!(p.passes.len(), 1);
    assert_eq!(p.passes[0].inputs[0].resource, Resource::Input { frame: 0 });
}

#[test]
fn colour_space_mismatch_on_float_inserts_a_conversion_pass_and_says_so() {
    let g = ok("EFFECT.c = { PASS = {
        enc = SHADER.s { img = IN  OUT.COLORSPACE = srgb }
        use = SHADER.s { img = PASS.enc }
    } OUT = use }");
    let (p, notes) = plan(&g, &InputDesc::rgba8_srgb(16, 16), &PlanOptions::default()).unwrap();
    let paths: Vec<&str> = p.passes.iter().map(|p| p.path.as_str()).collect();
    assert_eq!(paths, ["c/enc", "c/use:img:linear", "c/use"]);
    assert_eq!(notes.list.len(), 1);
    assert!(
        notes.list[0].message.contains("converting"),
        "{:?}",
        notes.list[0]
    );
    p.validate().unwrap();
}

#[test]
fn colour_space_mismatch_on_8_bit_is_a_free_view() {
    use fxgraph::graph::plan::View;
    let g = ok("EFFECT.c = { PASS = {
        enc = SHADER.s { img = IN  OUT.COLORSPACE = srgb  OUT.FORMAT = rgba8 }
        use = SHADER.s { img = PASS.enc }
        raw = SHADER.s { img = IN  img.COLORSPACE = srgb  other = PASS.use }
    } OUT = raw }");
    let (p, notes) = plan(&g, &InputDesc::rgba8_srgb(16, 16), &PlanOptions::default()).unwrap();
    assert!(notes.list.is_empty());
    assert_eq!(p.passes.len(), 3);
    assert_eq!(p.passes[1].inputs[0].view, View::SrgbDecode);
    assert_eq!(p.passes[2].inputs[0].view, View::Raw);
}

/// `COLORSPACE = stored`: the codes of an 8-bit input through raw views (no
/// conversion pass, no note) with the output written raw into an 8-bit sRGB target,
/// and a float input as stored (linear, no conversion).
#[test]
fn stored_colour_space_follows_the_input() {
    use fxgraph::graph::plan::View;
    use fxgraph::script::types::{ColorSpace, Format};
    let g = ok("EFFECT.c = { COLORSPACE = stored  PASS = {
        rows = SHADER.s { img = IN  OUT.FORMAT = rgba16f }
        weave = SHADER.s { img = IN  rows = PASS.rows  OUT.FORMAT = rgba32f }
    } OUT = weave }");
    let to_8bit = PlanOptions {
        output_format: Some(Format::Rgba8Srgb),
        ..Default::default()
    };
    let (p, notes) = plan(&g, &InputDesc::rgba8_srgb(16, 16), &to_8bit).unwrap();
    assert!(notes.list.is_empty(), "{:?}", notes.list);
    assert_eq!(p.passes.len(), 2);
    assert!(p.passes.iter().all(|p| p.colorspace == ColorSpace::Srgb));
    assert_eq!(p.passes[0].inputs[0].view, View::Raw);
    assert_eq!(p.passes[1].inputs[0].view, View::Raw);
    assert_eq!(p.passes[1].inputs[1].view, View::Natural);
    assert_eq!(p.passes[1].target_view, View::Raw);
    let float_in = InputDesc {
        format: Format::Rgba16f,
        ..InputDesc::rgba8_srgb(16, 16)
    };
    let (p, notes) = plan(&g, &float_in, &PlanOptions::default()).unwrap();
    assert!(notes.list.is_empty(), "{:?}", notes.list);
    assert_eq!(p.passes.len(), 2, "no conversion pass");
    assert!(p.passes.iter().all(|p| p.colorspace == ColorSpace::Linear));
    assert!(p
        .passes
        .iter()
        .all(|p| p.inputs.iter().all(|i| i.view == View::Natural)));
    p.validate().unwrap();
}

#[test]
fn every_shipped_effect_plans_at_the_lower_bound() {
    for (name, _) in library::builtin_effects() {
        let (g, d, s) = compile_chain(std::slice::from_ref(&name), &[]);
        assert!(!d.has_errors(), "{name}: {}", d.render(&s));
        let g = g.unwrap();
        for (w, h) in [(1920, 1080), (67, 41), (1, 1)] {
            let input = InputDesc::rgba8_srgb(w, h)
                .with_aux(&fxgraph::render::published_aux(true))
                .with_aux_of(&g);
            let (p, _) = plan(&g, &input, &PlanOptions::default())
                .unwrap_or_else(|d| panic!("{name}: {}", d.render(&s)));
            p.validate()
                .unwrap_or_else(|e| panic!("{name} {w}x{h}: {e}"));
            assert_eq!(p.peak_bytes, p.lower_bound_bytes, "{name} at {w}x{h}");
            assert!(p.naive_bytes >= p.peak_bytes);
        }
    }
}

/// A random DAG of `n` passes as a script: each pass reads 1-3 earlier passes or IN,
/// with a random scale and format; some read feedback.
fn random_script(spec: &[(Vec<usize>, usize, usize, bool)]) -> String {
    let scales = [
        "",
        "OUT.SCALE = 0.5",
        "OUT.SCALE = (0.25, 0.5)",
        "OUT.SIZE = (7, 3)",
        "OUT.SCALE = 2",
    ];
    let formats = [
        "",
        "OUT.FORMAT = rgba8",
        "OUT.FORMAT = r16f",
        "OUT.FORMAT = rgba32f",
        "OUT.FORMAT = IN",
    ];
    let mut s = String::from("EFFECT.r = {\n  PASS = {\n");
    for (i, (reads, scale, format, fb)) in spec.iter().enumerate() {
        s.push_str(&format!("    p{i} = SHADER.s {{"));
        for (k, &r) in reads.iter().enumerate() {
            if r >= i {
                s.push_str(&format!(" i{k} = IN"));
            } else {
                s.push_str(&format!(" i{k} = PASS.p{r}"));
            }
        }
        if *fb {
            s.push_str(&format!(" fb = PASS.p{i}[-1]"));
        }
        s.push_str(&format!(" {} {} }}\n", scales[*scale], formats[*format]));
    }
    s.push_str(&format!("  }}\n  OUT = p{}\n}}\n", spec.len() - 1));
    s
}

proptest! {
    // 256 cases per property in the test suite; PROPTEST_CASES=N for a long fuzz run.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256),
        ..ProptestConfig::default()
    })]

    /// On random DAGs: the plan never reads a freed value, never writes a slot that
    /// holds a live value, frees everything; MinPeak's peak equals the lower bound;
    /// Pool's peak is at least the lower bound.
    #[test]
    fn plans_of_random_dags_are_sound(
        spec in prop::collection::vec((prop::collection::vec(0usize..12, 1..4), 0usize..5, 0usize..5, prop::bool::weighted(0.1)), 1..12),
        w in 1u32..300, h in 1u32..300,
    ) {
        let text = random_script(&spec);
        let (g, d, s) = compile_text(&text);
        prop_assert!(!d.has_errors(), "{}\n{}", text, d.render(&s));
        let g = g.unwrap();
        for policy in [ReusePolicy::MinPeak, ReusePolicy::Pool] {
            let (p, _) = plan(&g, &InputDesc::rgba8_srgb(w, h), &PlanOptions { policy, output_format: None }).unwrap();
            let simulated = p.validate().map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
            prop_assert_eq!(simulated, p.peak_bytes);
            prop_assert!(p.peak_bytes >= p.lower_bound_bytes);
            prop_assert!(p.naive_bytes >= p.peak_bytes);
            if policy == ReusePolicy::MinPeak {
                prop_assert_eq!(p.peak_bytes, p.lower_bound_bytes, "{}", text);
            }
            // Every value is written by exactly one pass before it is read.
            let mut written = vec![false; p.values.len()];
            for step in &p.steps {
                if let Step::Run { pass } = step {
                    for i in &p.passes[*pass].inputs {
                        if let Resource::Value(v) = i.resource { prop_assert!(written[v]); }
                    }
                    if let Resource::Value(v) = p.passes[*pass].output { prop_assert!(!written[v]); written[v] = true; }
                }
            }
        }
    }

    /// The parser and compiler never panic, whatever the text.
    #[test]
    fn compiler_does_not_panic_on_arbitrary_text(text in "\\PC{0,300}") {
        let _ = compile_text(&text);
    }

    /// ... nor on scripts made of the language's own tokens in random order.
    #[test]
    fn compiler_does_not_panic_on_token_soup(tokens in prop::collection::vec(prop::sample::select(vec![
        "EFFECT", ".", "glow", "=", "{", "}", "PASS", "SHADER", "a", "b", "IN", "OUT", "(", ")", ",", "0.5", "-1", "[", "]",
        "PARAM", "FLOAT", "DEFAULT", "RANGE", "AUX", "depth", "OUT.SCALE", "OUT.SIZE", "OUT.FORMAT", "rgba8", "EFFECT.a", "PASS.a",
        "INCLUDE", "\"x.fx\"", "// c\n", "\n", "DEFINE.X", "true", "ENUM", "VALUES", "0", "99999999999", "IN[-1]", "PASS.a[-1]",
    ]), 0..80)) {
        let text = tokens.join(" ");
        let (g, _, _) = compile_text(&text);
        if let Some(g) = g {
            let _ = plan(&g, &InputDesc::rgba8_srgb(33, 17).with_aux(&fxgraph::render::published_aux(true)), &PlanOptions::default());
        }
    }
}

/// `--set e.k=v` on an effect `e` with a pass also named `e` sets the effect
/// parameter only (not a pass parameter `k` of pass `e`).
#[test]
fn effect_parameter_override_is_not_also_a_pass_override() {
    let g = clean_file(
        "e.fx",
        "EFFECT.e = { PARAM = { mode = ENUM { VALUES = (a, b)  DEFAULT = a } } PASS = { e = SHADER.s { img = IN  m = PARAM.mode } } OUT = e }",
        &["e.mode=b"],
    );
    let pass = g.pass(g.schedule[0]);
    assert_eq!(pass.params.len(), 1);
    assert_eq!(
        (pass.params[0].name.as_str(), pass.params[0].value[0]),
        ("m", 1.0)
    );
}

/// The graph layer reads no file: scripts come from an `EffectSource`. An
/// in-memory one serves an entry, an `INCLUDE` and an effect instantiated by name;
/// the default source is the built-in library alone.
#[test]
fn scripts_come_from_the_effect_source() {
    use fxgraph::graph::source::{EffectSource, Found, IncludeError, Origin};
    #[derive(Debug)]
    struct Memory;
    fn found(name: &str, text: &str) -> Found {
        Found {
            origin: Origin::Embedded(name.into()),
            shown: format!("mem:{name}"),
            text: text.into(),
            key: name.into(),
        }
    }
    impl EffectSource for Memory {
        fn entry(&self, arg: &str) -> Result<Option<Found>, String> {
            Ok((arg == "top").then(|| {
                found(
                    "top.fx",
                    "INCLUDE \"lib.fx\"\nEFFECT.top = { PASS = { a = EFFECT.inner { IN = IN } } OUT = a }",
                )
            }))
        }
        fn named(&self, name: &str) -> Result<Option<Found>, String> {
            Ok((name == "inner").then(|| {
                found(
                    "inner.fx",
                    "EFFECT.inner = { PASS = { p = SHADER.copy { img = IN } } OUT = p }",
                )
            }))
        }
        fn include(&self, _: &Origin, target: &str) -> Result<Found, IncludeError> {
            match target {
                "lib.fx" => Ok(found("lib.fx", "")),
                _ => Err(IncludeError::NotFound),
            }
        }
    }
    let (g, d, s) = compile(&CompileRequest {
        effects: vec!["top".into()],
        source: Some(std::sync::Arc::new(Memory)),
        ..Default::default()
    });
    assert!(g.is_some(), "{}", d.render(&s));
    assert_eq!(g.unwrap().schedule.len(), 1);
    // The default: built-in names work, a path is not read.
    let (g, d, s) = compile(&CompileRequest {
        effects: vec!["glow".into()],
        ..Default::default()
    });
    assert!(g.is_some(), "{}", d.render(&s));
    let (g, d, s) = compile(&CompileRequest {
        effects: vec!["effects/glow.fx".into()],
        ..Default::default()
    });
    assert!(g.is_none());
    assert!(d.render(&s).contains("reads no files"), "{}", d.render(&s));
}
