//! Frame sequences through an effect ([`run_sequence`]): frames of one size in order,
//! through a [`crate::gpu::stream::Stream`] (history, feedback, latency, field rate),
//! on the one pipeline of [`super::pipeline`].
//!
//! Memory is bounded for any sequence length: at most `queue` decoded frames wait
//! for the GPU, the stream holds `history + latency + 1` input textures, the plan's
//! transient textures (its `Pool` peak) and feedback rings, and at most `queue`
//! read-back frames wait for the encoder.

use super::effect::Effect;
use super::error::RunError;
use super::pipeline::{run_frames, Device, FrameSink, FrameSource, Mode, PipelineOptions};
use super::planes::PlaneConversion;
use super::report::{JobKind, Progress, RunReport};
use crate::gpu::executor::CameraStd;
use crate::script::types::Format;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Options of [`run_sequence`].
#[derive(Debug, Clone)]
pub struct SequenceOptions {
    /// Texture format of the output (rgba8-srgb for 8-bit files, rgba16f/32f for EXR).
    pub output_format: Format,
    pub assume_linear: bool,
    /// Outputs per input frame (2: field-rate deinterlacing).
    pub rate: u32,
    pub fps: f64,
    /// Input frame numbers whose outputs are written (a shard); frames outside it
    /// are read only as context (history/future/warm-up). `None`: all.
    pub emit: Option<(u64, u64)>,
    /// Depth of each queue between stages.
    pub queue: usize,
    pub timings: bool,
    /// Where the Y'CbCr frames of y4m and video streams are converted.
    pub ycbcr: PlaneConversion,
    /// The viewport: the output size passes scale from as `VIEWPORT` (`None`:
    /// each input's size; `fxrun --size`).
    pub viewport: Option<(u32, u32)>,
    /// Auxiliary images (`AUX.NAME`) given to every frame: `--aux NAME=FILE`
    /// and a slang preset's LUTs; each keeps its own size.
    pub aux: Vec<(String, PathBuf)>,
}

impl Default for SequenceOptions {
    fn default() -> Self {
        SequenceOptions {
            output_format: Format::Rgba8Srgb,
            assume_linear: false,
            rate: 1,
            fps: 25.0,
            emit: None,
            queue: 3,
            timings: false,
            ycbcr: PlaneConversion::Auto,
            viewport: None,
            aux: Vec::new(),
        }
    }
}

/// Run `effect` over every frame of `source`, writing to `sink`. `stop` ends the
/// run early (Ctrl-C): frames already written stay, frames in flight are finished.
/// Any failed frame ends the run with its error. With [`Device::Create`] the device
/// is made while the first frames decode.
#[allow(clippy::too_many_arguments)]
pub fn run_sequence(
    device: Device,
    effect: &mut Effect,
    source: Box<dyn FrameSource>,
    sink: Box<dyn FrameSink>,
    opts: &SequenceOptions,
    camera: Option<CameraStd>,
    stop: Arc<AtomicBool>,
    progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let p = PipelineOptions {
        mode: Mode::Sequence,
        job: JobKind::Sequence,
        output_format: opts.output_format,
        output_formats: Vec::new(),
        assume_linear: opts.assume_linear,
        rate: opts.rate,
        fps: opts.fps,
        emit: opts.emit,
        camera,
        keep_going: false,
        queue: opts.queue,
        timings: opts.timings,
        ycbcr: opts.ycbcr,
        viewport: opts.viewport,
    };
    let load = crate::io::LoadOptions {
        assume_linear: opts.assume_linear,
    };
    let source = super::sources::with_aux(source, super::sources::load_aux(&opts.aux, &load)?);
    run_frames(device, effect, source, sink, &p, stop, progress)
}
