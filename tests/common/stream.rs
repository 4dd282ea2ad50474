//! Running an effect of effects/ over a frame sequence through the streaming
//! runtime (`Stream`), for the temporal-effect tests.

use fxgraph::app::Effect;
use fxgraph::gpu::executor::Engine;
use fxgraph::gpu::stream::Stream;
use fxgraph::gpu::transfer::{input_format, read_pixels};
use fxgraph::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::Format;

pub fn effect_path(name: &str) -> String {
    format!("{}/effects/{name}.fx", env!("CARGO_MANIFEST_DIR"))
}

/// Run `effect` (a file in effects/) with `overrides` over `frames` at `rate`
/// outputs per frame; returns every output, in order, as linear RGBA f32.
pub fn run_stream(
    engine: &mut Engine,
    effect: &str,
    overrides: &[&str],
    frames: &[Image],
    rate: u32,
) -> Vec<Vec<f32>> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let mut fx = Effect::compile(&[effect_path(effect)], &o).unwrap_or_else(|e| panic!("{e}"));
    let (format, colorspace) = input_format(&frames[0], false);
    let input = InputDesc {
        width: frames[0].width,
        height: frames[0].height,
        format,
        colorspace,
        aux: vec![],
    };
    let opts = PlanOptions {
        policy: ReusePolicy::Pool,
        output_format: Some(Format::Rgba32f),
    };
    let prepared = fx
        .prepare_with(engine, &input, &opts)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut stream = Stream::new(engine, prepared, format);
    stream.rate = rate;
    let mut outs = Vec::new();
    let take = |i: u64, engine: &mut Engine, stream: &Stream, outs: &mut Vec<Vec<f32>>| {
        assert_eq!(i, outs.len() as u64, "outputs in order");
        let Pixels::F32(px) = read_pixels(&engine.ctx, stream.output(), Format::Rgba32f).unwrap()
        else {
            panic!("float output expected")
        };
        outs.push(px);
    };
    for f in frames {
        stream.push_image(engine, f).unwrap();
        while let Some(i) = stream.next(engine).unwrap() {
            take(i, engine, &stream, &mut outs);
        }
    }
    stream.end();
    while let Some(i) = stream.next(engine).unwrap() {
        take(i, engine, &stream, &mut outs);
    }
    assert_eq!(
        outs.len(),
        frames.len() * rate as usize,
        "{rate} output(s) per input frame"
    );
    outs
}

/// One input frame with its own auxiliary images (`AUX.name`) and the sub-pixel
/// jitter it was rendered with (the standard value `jitter`).
pub struct SeqFrame {
    pub image: Image,
    pub aux: Vec<(String, Image)>,
    pub jitter: [f32; 2],
}

/// An effect of effects/ by name, or a path to a `.fx` file as it is.
fn effect_arg(effect: &str) -> String {
    if effect.ends_with(".fx") {
        effect.to_string()
    } else {
        effect_path(effect)
    }
}

/// Run `effect` (a name in effects/ or a `.fx` path) with `overrides` over `frames`
/// through a `Stream` at `fps`, each frame pushed with its own aux images and jitter
/// (`Stream::push_image_with`); returns every output as linear RGBA f32. Inputs
/// and aux images are uploaded as `fxrun` does (`input_format`: float images as
/// rgba16f).
pub fn run_stream_frames(
    engine: &mut Engine,
    effect: &str,
    overrides: &[&str],
    frames: &[SeqFrame],
    fps: f64,
) -> Vec<Vec<f32>> {
    use fxgraph::gpu::stream::FrameData;
    use fxgraph::gpu::transfer::upload_image;
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let mut fx = Effect::compile(&[effect_arg(effect)], &o).unwrap_or_else(|e| panic!("{e}"));
    let (format, colorspace) = input_format(&frames[0].image, false);
    let input = InputDesc {
        width: frames[0].image.width,
        height: frames[0].image.height,
        format,
        colorspace,
        aux: frames[0]
            .aux
            .iter()
            .map(|(n, a)| (n.clone(), input_format(a, false).0))
            .collect(),
    };
    let opts = PlanOptions {
        policy: ReusePolicy::Pool,
        output_format: Some(Format::Rgba32f),
    };
    let mut prepared = fx
        .prepare_with(engine, &input, &opts)
        .unwrap_or_else(|e| panic!("{e}"));
    prepared.fps = fps;
    let mut stream = Stream::new(engine, prepared, format);
    let mut outs = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        let mut data = FrameData {
            jitter: f.jitter,
            ..Default::default()
        };
        for (n, a) in &f.aux {
            let fmt = input_format(a, false).0;
            let tex = upload_image(&engine.ctx, &format!("aux {n} {i}"), a, fmt).unwrap();
            data.aux.insert(n.clone(), tex);
        }
        stream.push_image_with(engine, &f.image, data).unwrap();
        while let Some(k) = stream.next(engine).unwrap() {
            assert_eq!(k, outs.len() as u64, "outputs in order");
            let Pixels::F32(px) =
                read_pixels(&engine.ctx, stream.output(), Format::Rgba32f).unwrap()
            else {
                panic!("float output expected")
            };
            outs.push(px);
        }
    }
    stream.end();
    assert!(
        stream.next(engine).unwrap().is_none(),
        "no latency expected"
    );
    assert_eq!(outs.len(), frames.len());
    outs
}
