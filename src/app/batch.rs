//! Batches of still images through one compiled effect, in one process: the device, the
//! compiled pipelines and (while the size stays the same) the plan and its textures are
//! reused from one image to the next.
//!
//! Every image is run as a one-frame still, exactly as [`super::still::apply_to_image`]
//! runs it (frame 0, `time` 0, every `IN[n]` the image itself), so the images are
//! independent and may differ in size: the effect is planned again (and its textures
//! allocated again) only when the input size or format, or the output format, changes.
//! An effect that reads other frames (`IN[±n]`, feedback) is a sequence, not a batch:
//! see [`super::sequence`].
//!
//! A batch is a run of [`super::pipeline`] in `Mode::Stills`: a decode thread reads
//! and decodes the next images, this thread runs the GPU, and an encode thread waits
//! for each read-back and writes the file (atomically: a failed image never leaves a
//! partial file, and an existing output is replaced only by a complete one).
//!
//! A failed image (unreadable, corrupt, too large, unwritable output) is recorded in
//! [`RunReport::failed`]; with [`BatchOptions::keep_going`] the other images go on,
//! otherwise the batch stops there: the images before it are finished and written, the
//! ones after it are not started.

use super::effect::Effect;
use super::error::RunError;
use super::pipeline::{run_frames, Device, Mode, PipelineOptions};
use super::report::{JobKind, Progress, RunReport};
use super::sources::{FilesSink, FilesSource, OutputNames};
use super::still::output_format_for;
use crate::io::{LoadOptions, SaveOptions};
use crate::script::types::Format;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// One image of a batch: where it comes from and where its result goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BatchItem {
    pub input: PathBuf,
    pub output: PathBuf,
}

/// Options of [`run_batch`].
#[derive(Debug, Clone)]
pub struct BatchOptions {
    /// Bits per channel of the output files (`None`: each format's default).
    pub bit_depth: Option<u8>,
    /// Treat 8/16-bit files as linear data.
    pub assume_linear: bool,
    /// Go on after a failed image (the default is to stop at the first one).
    pub keep_going: bool,
    /// Images held between the stages (decoded, waiting for the GPU; read back,
    /// waiting for the encoder).
    pub queue: usize,
    /// Collect per-pass GPU timings (of the last image, in [`RunReport::passes`]).
    pub timings: bool,
    /// The viewport: the output size passes scale from as `VIEWPORT` (`None`:
    /// each input's size; `fxrun --size`).
    pub viewport: Option<(u32, u32)>,
    /// Auxiliary images (`AUX.NAME`) given to every frame: `--aux NAME=FILE`
    /// and a slang preset's LUTs; each keeps its own size.
    pub aux: Vec<(String, PathBuf)>,
}

impl Default for BatchOptions {
    fn default() -> Self {
        BatchOptions {
            bit_depth: None,
            assume_linear: false,
            keep_going: false,
            queue: 2,
            timings: false,
            viewport: None,
            aux: Vec::new(),
        }
    }
}

/// Run `effect` on every image of `items`, writing each result to its output.
///
/// The output formats are checked for every item before any work starts (an output the
/// chosen format cannot be written as is an error, and nothing is written). Per-image
/// failures are in the report; `Err` is returned only when the batch cannot run at all
/// (an output format refused, the effect or its shaders rejected, a thread that cannot
/// start). `stop` ends the batch early: images in flight are finished. With
/// [`Device::Create`] the device is made while the first image decodes.
pub fn run_batch(
    device: Device,
    effect: &mut Effect,
    items: &[BatchItem],
    opts: &BatchOptions,
    stop: Arc<AtomicBool>,
    progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let output_formats = items
        .iter()
        .map(|it| output_format_for(&it.output, opts.bit_depth, opts.assume_linear))
        .collect::<Result<Vec<Format>, _>>()?;
    let load = LoadOptions {
        assume_linear: opts.assume_linear,
    };
    let source = FilesSource::new(
        items
            .iter()
            .enumerate()
            .map(|(i, it)| (i as u64, it.input.clone()))
            .collect(),
        load,
    );
    let sink = FilesSink {
        names: OutputNames::Named(
            (0u64..)
                .zip(items.iter().map(|it| it.output.clone()))
                .collect(),
        ),
        save: SaveOptions {
            bit_depth: opts.bit_depth,
            assume_linear: opts.assume_linear,
        },
    };
    let p = PipelineOptions {
        mode: Mode::Stills,
        job: JobKind::Batch,
        output_format: output_formats.first().copied().unwrap_or(Format::Rgba8Srgb),
        output_formats,
        assume_linear: opts.assume_linear,
        keep_going: opts.keep_going,
        queue: opts.queue,
        timings: opts.timings,
        viewport: opts.viewport,
        ..Default::default()
    };
    let aux = super::sources::load_aux(&opts.aux, &load)?;
    run_frames(
        device,
        effect,
        super::sources::with_aux(Box::new(source), aux),
        Box::new(sink),
        &p,
        stop,
        progress,
    )
}
