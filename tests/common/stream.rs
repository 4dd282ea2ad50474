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
    (width, height): (u32, u32),
    format: Format,
    colorspace: ColorSpace,
) -> Stream {
    let input = InputDesc {
        width,
        height,
        format,
        colorspace,
        aux: vec![],
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
