//! Sub-pixel jitter on demand: the `JITTER = halton23` declaration, what the
//! compiled graph, the plan and a prepared effect report, and the standard value
//! `jitter` reaching a shader (per frame, through `FrameInputs` and the stream's
//! per-frame data).

use crate::common;

use common::stream::{run_stream_frames, SeqFrame};
use fxgraph::app::Effect;
use fxgraph::gpu::executor::FrameInputs;
use fxgraph::gpu::transfer::{create_output, read_pixels, upload_image};
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::graph::{compile, CompileRequest, Graph};
use fxgraph::io::Pixels;
use fxgraph::script::types::Format;
use fxgraph::script::{halton23, Diagnostics, JitterPattern, SourceMap};

fn compile_text(dir: &tempfile::TempDir, text: &str) -> (Option<Graph>, Diagnostics, SourceMap) {
    let p = dir.path().join("t.fx");
    std::fs::write(&p, text).unwrap();
    common::compile::compile_file(&p)
}

const JITTERED: &str = "EFFECT.acc = {
    JITTER = halton23
    PASS = { a = SHADER.avg { cur = IN  hist = PASS.a[-1] } }
    OUT = a
}";

#[test]
fn the_declaration_reaches_the_graph_and_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let (g, d, s) = compile_text(&dir, JITTERED);
    assert!(d.is_empty(), "{}", d.render(&s));
    let g = g.unwrap();
    assert_eq!(g.jitter, Some(JitterPattern::Halton23));
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(32, 32), &PlanOptions::default()).unwrap();
    assert_eq!(p.jitter, Some(JitterPattern::Halton23));
    assert!(p.wants_jitter());
    assert_eq!(p.to_json()["jitter"], "halton23");
    assert!(p.render().contains("jitter: halton23"), "{}", p.render());

    // Without the declaration: no jitter.
    let (g, d, s) = compile_text(&dir, &JITTERED.replace("JITTER = halton23", ""));
    assert!(d.is_empty(), "{}", d.render(&s));
    let g = g.unwrap();
    assert_eq!(g.jitter, None);
    let (p, _) = plan(&g, &InputDesc::rgba8_srgb(32, 32), &PlanOptions::default()).unwrap();
    assert!(!p.wants_jitter());
    assert!(p.to_json()["jitter"].is_null());

    // An instance of a jittered effect asks for it; a culled one does not.
    let nested = format!(
        "{JITTERED}\nEFFECT.outer = {{ PASS = {{ t = EFFECT.acc {{ IN = IN }}  g = SHADER.grade {{ img = PASS.t }} }} OUT = g }}"
    );
    let (g, d, s) = compile_text(&dir, &nested);
    assert!(!d.has_errors(), "{}", d.render(&s));
    assert_eq!(g.unwrap().jitter, Some(JitterPattern::Halton23));
    let culled = format!(
        "{JITTERED}\nEFFECT.outer = {{ PASS = {{ t = EFFECT.acc {{ IN = IN }}  g = SHADER.grade {{ img = IN }} }} OUT = g }}"
    );
    let (g, d, s) = compile_text(&dir, &culled);
    assert!(!d.has_errors(), "{}", d.render(&s));
    assert_eq!(d.warning_count(), 1, "the culled pass is reported");
    assert_eq!(g.unwrap().jitter, None);

    // Built-ins: taa asks for it, the others do not.
    for (name, want) in [
        ("taa", Some(JitterPattern::Halton23)),
        ("fxaa", None),
        ("motion_blur", None),
        ("auto_exposure", None),
    ] {
        let (g, d, s) = compile(&CompileRequest {
            effects: vec![name.into()],
            ..Default::default()
        });
        assert!(!d.has_errors(), "{name}: {}", d.render(&s));
        assert_eq!(g.unwrap().jitter, want, "{name}");
    }
    // A chain with taa in it.
    let (g, _, _) = compile(&CompileRequest {
        effects: vec!["taa".into(), "tonemap".into()],
        ..Default::default()
    });
    assert_eq!(g.unwrap().jitter, Some(JitterPattern::Halton23));
}

#[test]
fn mistakes_in_the_declaration_are_reported_with_their_place() {
    let dir = tempfile::tempdir().unwrap();
    for (bad, message, note) in [
        (
            "JITTER = halton32",
            "unknown jitter sequence `halton32`",
            "did you mean `halton23`?",
        ),
        (
            "JITTER = 2",
            "`JITTER` expects a jitter sequence name (`halton23`), found a number",
            "",
        ),
    ] {
        let (g, d, s) = compile_text(&dir, &JITTERED.replace("JITTER = halton23", bad));
        assert!(g.is_none());
        let text = d.render(&s);
        assert!(text.contains(message), "{text}");
        assert!(text.contains(note), "{text}");
        assert!(text.contains("t.fx:2:"), "{text}");
    }
    let (_, d, s) = compile_text(&dir, &JITTERED.replace("JITTER", "JITTR"));
    let text = d.render(&s);
    assert!(text.contains("COLORSPACE and JITTER"), "{text}");
}

const SHOW: &str = "// The standard values `jitter` and `frame` as colour.
@group(0) @binding(0) var img: texture_2d<f32>;
struct Params {
    jitter: vec2<f32>,
    frame: f32,
}
@group(0) @binding(1) var<uniform> params: Params;
@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(img, vec2<i32>(pos.xy), 0);
    return vec4<f32>(params.jitter, params.frame, c.a);
}
";

fn show_effect(dir: &tempfile::TempDir) -> String {
    common::cli::write_effect(
        dir.path(),
        "show",
        "EFFECT.show = { JITTER = halton23  PASS = { s = SHADER.show_jitter { img = IN  OUT.FORMAT = rgba32f } } OUT = s }",
        ("show_jitter", SHOW),
    )
}

#[test]
fn the_standard_value_reaches_a_shader_per_frame() {
    let Some(mut engine) = common::engine() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let fx = show_effect(&dir);
    // Through a stream: each frame pushed with its Halton offset.
    let frames: Vec<SeqFrame> = (0..20u64)
        .map(|i| SeqFrame {
            image: common::image_f32(3, 2, |_, _| [0.5, 0.5, 0.5, 1.0]),
            aux: vec![],
            jitter: halton23(i),
        })
        .collect();
    let outs = run_stream_frames(&mut engine, &fx, &[], &frames, 25.0);
    for (i, out) in outs.iter().enumerate() {
        let j = halton23(i as u64);
        for px in out.chunks(4) {
            assert_eq!(px, [j[0], j[1], i as f32, 1.0], "frame {i}");
        }
    }
    // Through Prepared::run: the offset given with the frame, and 0 by default.
    let mut effect = Effect::compile(std::slice::from_ref(&fx), &[]).unwrap();
    assert_eq!(effect.jitter(), Some(JitterPattern::Halton23));
    let img = common::image_f32(3, 2, |_, _| [0.5, 0.5, 0.5, 1.0]);
    let mut prepared = effect
        .prepare(
            &mut engine,
            &InputDesc {
                format: Format::Rgba16f,
                ..InputDesc::rgba8_srgb(3, 2)
            },
            Some(Format::Rgba32f),
        )
        .unwrap();
    assert_eq!(prepared.jitter(), Some(JitterPattern::Halton23));
    let ctx = engine.ctx.clone();
    let tex = upload_image(&ctx, "jitter test input", &img, Format::Rgba16f).unwrap();
    let out = create_output(&ctx, 3, 2, Format::Rgba32f);
    let read = |engine: &mut fxgraph::gpu::executor::Engine| -> Vec<f32> {
        let Pixels::F32(v) = read_pixels(&engine.ctx, &out, Format::Rgba32f).unwrap() else {
            panic!("float output expected")
        };
        v
    };
    for (inputs, want) in [
        (
            FrameInputs::single(&tex).with_jitter([0.25, -0.375]),
            [0.25, -0.375],
        ),
        (FrameInputs::single(&tex), [0.0, 0.0]),
    ] {
        prepared.frame = 0;
        prepared.run(&mut engine, &inputs, &out, false).unwrap();
        let v = read(&mut engine);
        assert_eq!(&v[..2], &want);
    }
    // An effect without the declaration reports no jitter.
    let mut fxaa = Effect::compile(&["fxaa".to_string()], &[]).unwrap();
    assert_eq!(fxaa.jitter(), None);
    let p = fxaa
        .prepare(&mut engine, &InputDesc::rgba8_srgb(8, 8), None)
        .unwrap();
    assert_eq!(p.jitter(), None);
}
