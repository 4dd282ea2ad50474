//! Running a compiled effect chain on an image in memory ([`apply_in_memory`]): a
//! one-frame run of the pipeline from and to memory.

use super::effect::Effect;
use super::error::RunError;
use super::pipeline::{run_frames, Device, Mode, PipelineOptions};
use super::report::JobKind;
use super::sources::{MemorySink, MemorySource};
use crate::gpu::executor::Engine;
use crate::pixels::{Image, Pixels};
use crate::script::types::Format;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Apply an effect chain to an in-memory image on `engine`; returns the output
/// size and pixels read back in `out_format` (rgba8-srgb gives sRGB-encoded U8,
/// rgba16f/rgba32f give linear F32). A one-frame run of the pipeline
/// ([`super::pipeline::run_frames`]) from and to memory, exactly as a one-image
/// `fxrun` run. Used by tests and Rust programs.
pub fn apply_in_memory(
    engine: &mut Engine,
    effects: &[String],
    overrides: &[String],
    img: &Image,
    aux: &[(String, &Image)],
    out_format: Format,
    assume_linear: bool,
) -> Result<(u32, u32, Pixels), RunError> {
    let mut effect = Effect::compile(effects, overrides)?;
    let source = MemorySource::new(vec![img.clone()])
        .with_aux(aux.iter().map(|(n, a)| (n.clone(), (*a).clone())).collect());
    let sink = MemorySink::default();
    let frames = sink.frames();
    let opts = PipelineOptions {
        mode: Mode::Stills,
        job: JobKind::Image,
        output_format: out_format,
        assume_linear,
        queue: 1,
        ..Default::default()
    };
    let mut report = run_frames(
        Device::Engine(engine),
        &mut effect,
        Box::new(source),
        Box::new(sink),
        &opts,
        Arc::new(AtomicBool::new(false)),
        |_| {},
    )?;
    if let Some(f) = report.failed.drain(..).next() {
        return Err(f.error);
    }
    let mut frames = frames.lock().unwrap_or_else(|e| e.into_inner());
    let (_, width, height, pixels) = frames
        .pop()
        .ok_or_else(|| RunError::Other("the run wrote no frame".into()))?;
    Ok((width, height, pixels))
}
