//! Batches of still images through one compiled effect, in one process: the device, the
//! compiled pipelines and (while the size stays the same) the plan and its textures are
//! reused from one image to the next.
//!
//! Every image is run as a one-frame still, exactly as [`super::runner::apply_to_image`]
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
//! [`BatchReport::failed`]; with [`BatchOptions::keep_going`] the other images go on,
//! otherwise the batch stops there: the images before it are finished and written, the
//! ones after it are not started.

use super::executor::{wgpu_format, Engine, FrameInputs, PassTiming, Prepared};
use super::runner::{
    create_output, image_bytes, input_format, output_format_for, pixels_from_bytes, Effect,
    RunError,
};
use super::sequence::Progress;
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
    /// Collect per-pass GPU timings (of the last image, in [`BatchReport::passes`]).
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

/// An image of the batch that failed.
#[derive(Debug, serde::Serialize)]
pub struct BatchFailure {
    /// Position of the image in the batch.
    pub index: usize,
    pub input: PathBuf,
    /// The error, rendered (it names the file).
    pub message: String,
    #[serde(skip)]
    pub error: RunError,
}

/// An image of the batch that was written.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ImageDone {
    pub index: usize,
    pub input: PathBuf,
    pub output: PathBuf,
    /// Size of the output.
    pub width: u32,
    pub height: u32,
    /// Time spent reading and decoding the input.
    pub decode_ms: f64,
    /// Time spent on the GPU thread (planning when the size changed, upload, passes).
    pub gpu_ms: f64,
    /// Time spent waiting for the read-back, converting and writing the output.
    pub encode_ms: f64,
}

impl ImageDone {
    /// The image's own processing time: decode + GPU + encode (its time in the queues
    /// between the stages not counted).
    pub fn total_ms(&self) -> f64 {
        self.decode_ms + self.gpu_ms + self.encode_ms
    }
}

/// What a batch did and where its time went.
#[derive(Debug, Default, serde::Serialize)]
pub struct BatchReport {
    pub adapter: String,
    /// Images in the batch.
    pub images: usize,
    /// Images written, in batch order.
    pub done: Vec<ImageDone>,
    /// Images that failed, in batch order.
    pub failed: Vec<BatchFailure>,
    /// Times the effect was planned and its textures allocated (once per run of
    /// images of the same size and formats).
    pub plans: usize,
    pub wall_ms: f64,
    /// Busy time of each stage.
    pub decode_busy_ms: f64,
    pub gpu_busy_ms: f64,
    pub encode_busy_ms: f64,
    /// Per-pass timings of the last image (with [`BatchOptions::timings`]).
    pub passes: Vec<PassTiming>,
    /// Stopped early by the `stop` flag (Ctrl-C).
    pub interrupted: bool,
}

impl BatchReport {
    /// Images neither written nor failed: those after the failure that stopped the
    /// batch, or after an interruption.
    pub fn not_run(&self) -> usize {
        self.images - self.done.len() - self.failed.len()
    }

    /// Median of the written images' processing times ([`ImageDone::total_ms`]), 0 when
    /// none was written.
    pub fn median_ms(&self) -> f64 {
        let mut t: Vec<f64> = self.done.iter().map(ImageDone::total_ms).collect();
        if t.is_empty() {
            return 0.0;
        }
        t.sort_by(f64::total_cmp);
        let n = t.len();
        if n % 2 == 1 {
            t[n / 2]
        } else {
            (t[n / 2 - 1] + t[n / 2]) / 2.0
        }
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
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
type Encoded = (
    usize,
    super::context::PendingReadback,
    Format,
    Duration,
    Duration,
);

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
) -> Result<BatchReport, RunError> {
    let start = Instant::now();
    let out_formats = items
        .iter()
        .map(|it| output_format_for(&it.output, opts.bit_depth, opts.assume_linear))
        .collect::<Result<Vec<_>, _>>()?;
    let mut report = BatchReport {
        adapter: engine.ctx.info.name.clone(),
        images: items.len(),
        ..Default::default()
    };
    let queue = opts.queue.max(1);
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
                    Ok(()) => done.push(ImageDone {
                        index: i,
                        input: input.clone(),
                        output: output.clone(),
                        width: w,
                        height: h,
                        decode_ms: ms(decode),
                        gpu_ms: ms(gpu),
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
    report.decode_busy_ms = ms(decode_busy);
    report.gpu_busy_ms = ms(gpu_busy);
    report.encode_busy_ms = ms(encode_busy);
    report.wall_ms = ms(start.elapsed());
    Ok(report)
}

fn failure(index: usize, input: &std::path::Path, error: RunError) -> BatchFailure {
    BatchFailure {
        index,
        input: input.to_path_buf(),
        message: error.to_string(),
        error,
    }
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
    report: &mut BatchReport,
) -> Result<super::context::PendingReadback, RunError> {
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
    let passes = c.prepared.run(engine, &inputs, &c.output, opts.timings)?;
    if opts.timings {
        report.passes = passes;
    }
    let mut enc = ctx
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("fxgraph batch readback"),
        });
    let pending = ctx.encode_readback(&mut enc, &c.output)?;
    ctx.queue.submit([enc.finish()]);
    Ok(pending)
}
