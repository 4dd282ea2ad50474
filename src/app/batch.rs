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
//! The work is pipelined like a sequence: a decode thread reads and decodes the next
//! images, this thread runs the GPU, and an encode thread waits for each read-back and
//! writes the file (atomically: a failed image never leaves a partial file, and an
//! existing output is replaced only by a complete one).
//!
//! A failed image (unreadable, corrupt, too large, unwritable output) is recorded in
//! [`RunReport::failed`]; with [`BatchOptions::keep_going`] the other images go on,
//! otherwise the batch stops there: the images before it are finished and written, the
//! ones after it are not started.

use super::effect::Effect;
use super::error::RunError;
use super::report::{ms, FrameDone, FrameFailure, JobKind, MemoryReport, Progress, RunReport};
use super::still::output_format_for;
use crate::gpu::context::PendingReadback;
use crate::gpu::executor::{wgpu_format, Engine, FrameInputs, Prepared};
use crate::gpu::transfer::{create_output, image_bytes, input_format, pixels_from_bytes};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{self, Image, IoError, LoadOptions, SaveOptions};
use crate::script::types::{ColorSpace, Format};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::sync::Arc;
use std::time::{Duration, Instant};

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
}

impl Default for BatchOptions {
    fn default() -> Self {
        BatchOptions {
            bit_depth: None,
            assume_linear: false,
            keep_going: false,
            queue: 2,
            timings: false,
        }
    }
}

/// What the plan and its textures depend on.
#[derive(Clone, Copy, PartialEq, Eq)]
struct PlanKey {
    width: u32,
    height: u32,
    input: Format,
    colorspace: ColorSpace,
    output: Format,
}

/// The effect prepared for one [`PlanKey`], with its input and output textures.
struct Current {
    key: PlanKey,
    prepared: Prepared,
    input: wgpu::Texture,
    output: wgpu::Texture,
}

/// A decoded image (or why it could not be), with its decode time.
type Decoded = (usize, Result<(Image, Duration), IoError>);
/// A read-back on its way to the encoder: index, copy, format, GPU-thread time, decode time.
type Encoded = (usize, PendingReadback, Format, Duration, Duration);

/// Run `effect` on every image of `items`, writing each result to its output.
///
/// The output formats are checked for every item before any work starts (an output the
/// chosen format cannot be written as is an error, and nothing is written). Per-image
/// failures are in the report; `Err` is returned only when the batch cannot run at all
/// (an output format refused, the effect or its shaders rejected, a thread that cannot
/// start). `stop` ends the batch early: images in flight are finished.
pub fn run_batch(
    engine: &mut Engine,
    effect: &mut Effect,
    items: &[BatchItem],
    opts: &BatchOptions,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let start = Instant::now();
    let out_formats = items
        .iter()
        .map(|it| output_format_for(&it.output, opts.bit_depth, opts.assume_linear))
        .collect::<Result<Vec<_>, _>>()?;
    let mut report = RunReport {
        job: JobKind::Batch,
        adapter: engine.ctx.info.name.clone(),
        backend: format!("{:?}", engine.ctx.info.backend),
        frames_total: Some(items.len() as u64),
        ..Default::default()
    };
    let queue = opts.queue.max(1);
    // Decoded images waiting for the GPU, the one on the GPU, read-backs waiting for
    // the encoder, and the one being encoded.
    report.frames_held_max = 2 * queue + 2;
    // Set when the batch must end early (a failure without keep_going, or `stop`).
    let halt = Arc::new(AtomicBool::new(false));
    let max_side = engine
        .ctx
        .device
        .limits()
        .max_texture_dimension_2d
        .min(io::MAX_SIDE);
    let load = LoadOptions {
        assume_linear: opts.assume_linear,
    };
    let (dec_tx, dec_rx) = sync_channel::<Decoded>(queue);
    let (enc_tx, enc_rx) = sync_channel::<Encoded>(queue);
    let inputs: Vec<PathBuf> = items.iter().map(|it| it.input.clone()).collect();
    let (halt_d, stop_d, keep_going) = (halt.clone(), stop.clone(), opts.keep_going);
    let decoder = std::thread::Builder::new()
        .name("fxgraph batch decode".into())
        .spawn(move || -> Duration {
            let mut busy = Duration::ZERO;
            for (i, path) in inputs.iter().enumerate() {
                if halt_d.load(Ordering::Relaxed) || stop_d.load(Ordering::Relaxed) {
                    break;
                }
                let t = Instant::now();
                let item = decode_one(path, max_side, &load);
                let spent = t.elapsed();
                busy += spent;
                let failed = item.is_err();
                if dec_tx.send((i, item.map(|img| (img, spent)))).is_err()
                    || (failed && !keep_going)
                {
                    break;
                }
            }
            busy
        })
        .map_err(|e| RunError::Other(format!("cannot start the decode thread: {e}")))?;
    let outputs: Vec<(PathBuf, PathBuf)> = items
        .iter()
        .map(|it| (it.input.clone(), it.output.clone()))
        .collect();
    let save = SaveOptions {
        bit_depth: opts.bit_depth,
        assume_linear: opts.assume_linear,
    };
    let halt_e = halt.clone();
    let encoder = std::thread::Builder::new()
        .name("fxgraph batch encode".into())
        .spawn(move || {
            let mut busy = Duration::ZERO;
            let mut done = Vec::new();
            let mut failed = Vec::new();
            for (i, pending, format, gpu, decode) in enc_rx {
                if !failed.is_empty() && !keep_going {
                    continue; // stopped: images after the failure are not written
                }
                let t = Instant::now();
                let (w, h) = (pending.width(), pending.height());
                let (input, output) = &outputs[i];
                let result = pending
                    .finish()
                    .and_then(|raw| pixels_from_bytes(raw, format))
                    .map_err(RunError::from)
                    .and_then(|px| io::save_image(output, w, h, &px, &save).map_err(Into::into));
                let spent = t.elapsed();
                busy += spent;
                match result {
                    Ok(()) => done.push(FrameDone {
                        index: i,
                        input: input.display().to_string(),
                        output: output.display().to_string(),
                        width: w,
                        height: h,
                        decode_ms: Some(ms(decode)),
                        gpu_ms: Some(ms(gpu)),
                        encode_ms: ms(spent),
                    }),
                    Err(e) => {
                        if !keep_going {
                            halt_e.store(true, Ordering::Relaxed);
                        }
                        failed.push(failure(i, input, e));
                    }
                }
            }
            (busy, done, failed)
        })
        .map_err(|e| RunError::Other(format!("cannot start the encode thread: {e}")))?;

    let mut gpu_busy = Duration::ZERO;
    let mut current: Option<Current> = None;
    let mut fatal: Option<RunError> = None;
    let mut through = 0u64;
    for (i, item) in &dec_rx {
        if halt.load(Ordering::Relaxed) {
            break;
        }
        report.frames_in += 1;
        let (img, decode_time) = match item {
            Ok(x) => x,
            Err(e) => {
                report.failed.push(failure(i, &items[i].input, e.into()));
                if !opts.keep_going {
                    halt.store(true, Ordering::Relaxed);
                    break;
                }
                continue;
            }
        };
        let t = Instant::now();
        match gpu_one(
            engine,
            effect,
            &mut current,
            &img,
            out_formats[i],
            opts,
            &mut report,
        ) {
            Ok(pending) => {
                let spent = t.elapsed();
                gpu_busy += spent;
                if enc_tx
                    .send((i, pending, out_formats[i], spent, decode_time))
                    .is_err()
                {
                    break;
                }
            }
            Err(e @ RunError::Rejected { .. }) => {
                // The effect or its shaders: every image would fail the same way.
                fatal = Some(e);
                halt.store(true, Ordering::Relaxed);
                break;
            }
            Err(e) => {
                gpu_busy += t.elapsed();
                // The textures may be in any state after a GPU error: plan afresh.
                current = None;
                report.failed.push(failure(i, &items[i].input, e));
                if !opts.keep_going {
                    halt.store(true, Ordering::Relaxed);
                    break;
                }
            }
        }
        through += 1;
        progress(Progress {
            done: through,
            total: Some(items.len() as u64),
            elapsed: start.elapsed(),
        });
        if stop.load(Ordering::Relaxed) {
            report.interrupted = true;
            break;
        }
    }
    drop(enc_tx);
    drop(dec_rx);
    let decode_busy = decoder.join().unwrap_or_default();
    let (encode_busy, done, enc_failed) = encoder
        .join()
        .map_err(|_| RunError::Other("the encode thread panicked".into()))?;
    if let Some(e) = fatal {
        return Err(e);
    }
    report.done = done;
    report.failed.extend(enc_failed);
    report.failed.sort_by_key(|f| f.index);
    report.stages.decode_busy_ms = ms(decode_busy);
    report.stages.gpu_busy_ms = ms(gpu_busy);
    report.stages.encode_busy_ms = ms(encode_busy);
    report.wall_ms = ms(start.elapsed());
    Ok(report)
}

fn failure(index: usize, input: &std::path::Path, error: RunError) -> FrameFailure {
    FrameFailure::new(index, input.display().to_string(), error)
}

/// Read an image file, refuse a size over `max_side` from its header, decode it.
fn decode_one(path: &std::path::Path, max_side: u32, load: &LoadOptions) -> Result<Image, IoError> {
    let bytes = io::read_image_file(path)?;
    let (w, h) = io::image_dimensions(&bytes, path)?;
    if w.max(h) > max_side {
        return Err(IoError::Decode {
            path: path.to_path_buf(),
            message: format!(
                "the image is {w}x{h}, larger than the GPU's limit of {max_side} pixels per side"
            ),
        });
    }
    io::decode_image(&bytes, path, load)
}

/// Run one image on the GPU (planning again if its size or formats differ from the
/// previous image's) and start reading its output back.
fn gpu_one(
    engine: &mut Engine,
    effect: &mut Effect,
    current: &mut Option<Current>,
    img: &Image,
    out_format: Format,
    opts: &BatchOptions,
    report: &mut RunReport,
) -> Result<PendingReadback, RunError> {
    let (in_format, colorspace) = input_format(img, opts.assume_linear);
    let key = PlanKey {
        width: img.width,
        height: img.height,
        input: in_format,
        colorspace,
        output: out_format,
    };
    let bytes = image_bytes(img, in_format);
    let ctx = engine.ctx.clone();
    let reuse = current.as_ref().is_some_and(|c| c.key == key);
    if reuse {
        let c = current.as_ref().expect("checked");
        let texel = (bytes.len() / (img.width as usize * img.height as usize)) as u32;
        ctx.queue.write_texture(
            c.input.as_image_copy(),
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(img.width * texel),
                rows_per_image: None,
            },
            c.input.size(),
        );
    } else {
        // Free the previous size's textures before allocating the new ones.
        *current = None;
        let desc = InputDesc {
            width: img.width,
            height: img.height,
            format: in_format,
            colorspace,
            aux: Vec::new(),
        };
        let plan_opts = PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(out_format),
        };
        // Transient textures come from the engine's pool, kept for the next image.
        let prepared = effect.prepare_with(engine, &desc, &plan_opts)?;
        report.plans += 1;
        report.memory = MemoryReport {
            peak_bytes: prepared.plan.peak_bytes,
            lower_bound_bytes: prepared.plan.lower_bound_bytes,
            naive_bytes: prepared.plan.naive_bytes,
        };
        let input = ctx.upload_texture(
            "fxgraph batch input",
            img.width,
            img.height,
            wgpu_format(in_format),
            &bytes,
            wgpu::TextureUsages::empty(),
        )?;
        let out = prepared.plan.output;
        let output = create_output(&ctx, out.width, out.height, out.format);
        *current = Some(Current {
            key,
            prepared,
            input,
            output,
        });
    }
    let c = current.as_mut().expect("prepared above");
    // Every image is a still of its own: frame 0, as a one-image run.
    c.prepared.frame = 0;
    c.prepared.subframe = 0;
    let inputs = FrameInputs::still(&c.input, &c.prepared.plan);
    // The passes and the copy into the read-back buffer: one submission.
    let output = &c.output;
    let (passes, pending) = c
        .prepared
        .run_then(engine, &inputs, output, opts.timings, |enc| {
            ctx.encode_readback(enc, output)
        })?;
    if opts.timings {
        report.passes = passes;
    }
    Ok(pending)
}
