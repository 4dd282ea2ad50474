//! Frame time of `Prepared::record` alone: an effect recorded into an encoder of
//! our own, submitted, and waited for, frame after frame, on an image (what the
//! viewer does each frame, without its panel and presentation). The reference of
//! `bench/viewer.sh`.
//!
//! `cargo run --release --example record_frames -- EFFECT IMAGE FRAMES`
//! prints the median frame time (after 2 warm-up frames) in ms.

use fxgraph::app::Effect;
use fxgraph::gpu::context::{AdapterChoice, GpuContext};
use fxgraph::gpu::executor::{Engine, FrameInputs};
use fxgraph::gpu::transfer::{create_output, input_format, upload_image};
use fxgraph::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [name, image, frames] = args.as_slice() else {
        return Err("usage: record_frames EFFECT IMAGE FRAMES".into());
    };
    let frames: usize = frames.parse()?;
    let img = fxgraph::io::load_image(std::path::Path::new(image), &Default::default())?;
    let mut engine = Engine::new(GpuContext::new(&AdapterChoice::Auto)?);
    let ctx = engine.ctx.clone();
    let (format, colorspace) = input_format(&img, false);
    let input = upload_image(&ctx, "input", &img, format)?;
    let desc = InputDesc {
        width: img.width,
        height: img.height,
        format,
        colorspace,
        aux: Vec::new(),
        aux_sizes: Vec::new(),
        viewport: None,
    };
    let mut effect = Effect::compile(std::slice::from_ref(name), &[])?;
    let opts = PlanOptions {
        policy: ReusePolicy::Pool,
        output_format: Some(fxgraph::script::types::Format::Rgba8Srgb),
    };
    let mut prepared = effect.prepare_with(&mut engine, &desc, &opts)?;
    let o = prepared.plan.output;
    let output = create_output(&ctx, o.width, o.height, o.format);
    let mut times = Vec::with_capacity(frames);
    for _ in 0..frames {
        let t = Instant::now();
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("record_frames"),
            });
        prepared.frame = 0;
        let inputs = FrameInputs::still(&input, &prepared.plan);
        prepared.record(&mut engine, &mut encoder, &inputs, &output)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| e.to_string())?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let mut steady = times[times.len().min(2)..].to_vec();
    steady.sort_by(f64::total_cmp);
    let median = steady.get(steady.len() / 2).copied().unwrap_or(0.0);
    println!(
        "record_frames: {name} {}x{}: {frames} frames; median frame {median:.2} ms (after the first 2)",
        img.width, img.height
    );
    Ok(())
}
