//! Running an effect of effects/ over a frame sequence through the streaming
//! runtime (`Stream`), for the temporal-effect tests.

use fxgraph::app::Effect;
use fxgraph::gpu::executor::Engine;
use fxgraph::gpu::stream::Stream;
use fxgraph::gpu::transfer::{input_format, read_pixels};
use fxgraph::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use fxgraph::io::{Image, Pixels};
use fxgraph::script::types::ColorSpace;
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
    let size = (frames[0].width, frames[0].height);
    let mut stream = stream_of(engine, &mut fx, size, format, colorspace);
    stream.rate = rate;
    let mut outs = Vec::new();
    let take = |i: u64, engine: &mut Engine, stream: &Stream, outs: &mut Vec<Vec<f32>>| {
        assert_eq!(i, outs.len() as u64, "outputs in order");
        outs.push(output_f32(engine, stream));
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

/// A stream of `effect` prepared for `size` frames uploaded as `format` in
/// `colorspace`, with the plan's buffers pooled and the output in rgba32f.
pub fn stream_of(
    engine: &mut Engine,
    effect: &mut Effect,
    size: (u32, u32),
    format: Format,
    colorspace: ColorSpace,
) -> Stream {
    stream_with_aux(engine, effect, size, format, colorspace, vec![])
}

/// [`stream_of`] for frames with the auxiliary images `aux` (names and formats).
pub fn stream_with_aux(
    engine: &mut Engine,
    effect: &mut Effect,
    (width, height): (u32, u32),
    format: Format,
    colorspace: ColorSpace,
    aux: Vec<(String, Format)>,
) -> Stream {
    let input = InputDesc {
        width,
        height,
        format,
        colorspace,
        aux,
        aux_sizes: Vec::new(),
        viewport: None,
    };
    let opts = PlanOptions {
        policy: ReusePolicy::Pool,
        output_format: Some(Format::Rgba32f),
    };
    let prepared = effect
        .prepare_with(engine, &input, &opts)
        .unwrap_or_else(|e| panic!("{e}"));
    Stream::new(engine, prepared, format)
}

/// The stream's current output, read back as RGBA f32.
pub fn output_f32(engine: &Engine, stream: &Stream) -> Vec<f32> {
    match read_pixels(&engine.ctx, stream.output(), Format::Rgba32f).unwrap() {
        Pixels::F32(px) => px,
        Pixels::U8(_) => panic!("float output expected"),
    }
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
    use fxgraph::gpu::stream::FrameExtras;
    use fxgraph::gpu::transfer::upload_image;
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let mut fx = Effect::compile(&[effect_arg(effect)], &o).unwrap_or_else(|e| panic!("{e}"));
    let first = &frames[0];
    let (format, colorspace) = input_format(&first.image, false);
    let aux = first
        .aux
        .iter()
        .map(|(n, a)| (n.clone(), input_format(a, false).0))
        .collect();
    let size = (first.image.width, first.image.height);
    let mut stream = stream_with_aux(engine, &mut fx, size, format, colorspace, aux);
    stream.prepared.fps = fps;
    let mut outs = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        let mut extras = FrameExtras {
            jitter: f.jitter,
            ..Default::default()
        };
        for (n, a) in &f.aux {
            let fmt = input_format(a, false).0;
            let tex = upload_image(&engine.ctx, &format!("aux {n} {i}"), a, fmt).unwrap();
            extras.aux.insert(n.clone(), tex);
        }
        stream.push_image_with(engine, &f.image, extras).unwrap();
        while let Some(k) = stream.next(engine).unwrap() {
            assert_eq!(k, outs.len() as u64, "outputs in order");
            outs.push(output_f32(engine, &stream));
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
