//! The one pipeline of every file and stream job: a [`FrameSource`] on a decode thread,
//! the compiled effect on the GPU (this thread), a [`FrameSink`] on an encode thread,
//! joined by bounded queues, so decoding the next frames and encoding the previous
//! ones overlap the GPU work on the current one. An image is a one-frame run, a batch
//! a run of independent stills, a sequence a run through a [`Stream`].
//!
//! - [`Mode::Stills`]: every frame is a still of its own (frame 0, `time` 0, every
//!   `IN[n]` the frame itself), so frames may differ in size: the effect is planned
//!   again (its textures allocated again) only when the input size or format, or the
//!   output format, changes. A failed frame is recorded in [`RunReport::failed`]; with
//!   `keep_going` the others go on, otherwise the run stops there (frames before it are
//!   finished and written, frames after it are not started).
//! - [`Mode::Sequence`]: the frames go through one [`Stream`] (history, feedback,
//!   latency, field rate), so they must have one size; the first failure ends the run
//!   with an error.
//!
//! Memory is bounded for any length: at most `queue` decoded frames wait for the GPU,
//! the stream (or the still's plan) holds its textures, at most `queue` read-backs
//! wait for the encoder. Each GPU frame is one submission: its passes and the copy of
//! its output into a read-back buffer.
//!
//! The device may be given ([`Device::Engine`]) or created by the run
//! ([`Device::Create`]), on a thread while the first frames are read and decoded; a
//! source checks each image's size from its header against [`SideLimit`] (which waits
//! for the device only for sizes above what every device takes) before decoding.

use super::effect::Effect;
use super::error::RunError;
use super::report::{ms, FrameDone, FrameFailure, JobKind, MemoryReport, Progress, RunReport};
use crate::gpu::context::{AdapterChoice, GpuContext, PendingReadback};
use crate::gpu::executor::{wgpu_format, CameraStd, Engine, FrameInputs, Prepared};
use crate::gpu::stream::Stream;
use crate::gpu::transfer::{
    create_output, image_bytes, input_format, pixels_from_bytes, upload_image,
};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{Image, IoError, Pixels};
use crate::script::types::{ColorSpace, Format};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// A frame from a source: its number, a name for messages (a file name, `stdin frame
/// N`), the decoded image or why it could not be, and auxiliary images (`AUX.NAME`).
pub struct SourceFrame {
    pub number: u64,
    pub name: String,
    pub image: Result<Image, IoError>,
    pub aux: Vec<(String, Image)>,
}

/// Where frames come from (runs on the decode thread).
pub trait FrameSource: Send {
    /// Number of frames, if known (for the progress bar and the report).
    fn frame_count(&self) -> Option<u64>;
    /// The next frame, or `None` at the end. A source that cannot go on after a failed
    /// frame (a broken stream) returns `None` after it.
    fn next_frame(&mut self) -> Option<SourceFrame>;
    /// The device's size limit, for sources that read sizes from headers.
    fn set_limit(&mut self, _limit: SideLimit) {}
}

/// Where output frames go (runs on the encode thread).
pub trait FrameSink: Send {
    /// Write output frame `number`; returns where it went (a file name, `stdout`).
    fn write(
        &mut self,
        number: u64,
        width: u32,
        height: u32,
        pixels: Pixels,
    ) -> Result<String, IoError>;
    /// Called once after the last frame.
    fn finish(&mut self) -> Result<(), IoError> {
        Ok(())
    }
}

/// The largest width or height the device takes, known once the device exists.
/// [`SideLimit::check`] answers sizes every device takes at once and waits for the
/// device only for larger ones, so decoding overlaps device creation.
#[derive(Clone, Default)]
pub struct SideLimit(Arc<(Mutex<Option<u32>>, Condvar)>);

impl SideLimit {
    /// A limit already known.
    pub fn known(max: u32) -> Self {
        let l = SideLimit::default();
        l.set(max);
        l
    }

    /// Set the limit (once the device exists, or when it failed: then any value).
    pub fn set(&self, max: u32) {
        let (m, cv) = &*self.0;
        *m.lock().unwrap_or_else(|e| e.into_inner()) = Some(max.min(crate::io::MAX_SIDE));
        cv.notify_all();
    }

    /// Ok when an image of `width` × `height` fits the device; Err with the limit.
    pub fn check(&self, width: u32, height: u32) -> Result<(), u32> {
        let side = width.max(height);
        if side <= wgpu::Limits::default().max_texture_dimension_2d {
            return Ok(());
        }
        let (m, cv) = &*self.0;
        let mut v = m.lock().unwrap_or_else(|e| e.into_inner());
        while v.is_none() {
            v = cv.wait(v).unwrap_or_else(|e| e.into_inner());
        }
        let max = v.expect("set");
        if side <= max {
            Ok(())
        } else {
            Err(max)
        }
    }
}

/// The device of a run.
pub enum Device<'a> {
    /// The caller's engine (its device, pipelines and pools are reused).
    Engine(&'a mut Engine),
    /// Create one (on a thread, while the first frames are decoded).
    Create(&'a AdapterChoice),
}

/// How frames relate (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Stills,
    Sequence,
}

/// Options of [`run_frames`].
#[derive(Debug, Clone)]
pub struct PipelineOptions {
    pub mode: Mode,
    /// The kind of job, for the report.
    pub job: JobKind,
    /// Texture format of the outputs (rgba8-srgb for 8-bit files, rgba16f/32f for EXR).
    pub output_format: Format,
    /// Per frame number, when outputs differ in file type (a batch to several
    /// formats); frames past its end use `output_format`.
    pub output_formats: Vec<Format>,
    pub assume_linear: bool,
    /// Outputs per input frame (2: field-rate deinterlacing). Sequences only.
    pub rate: u32,
    pub fps: f64,
    /// Input frame numbers whose outputs are written (a shard); frames outside it are
    /// read only as context. `None`: all. Sequences only.
    pub emit: Option<(u64, u64)>,
    /// Standard camera values for the effect (a rendered input).
    pub camera: Option<CameraStd>,
    /// Stills: go on after a failed frame (the default is to stop at the first one).
    pub keep_going: bool,
    /// Depth of each queue between stages.
    pub queue: usize,
    pub timings: bool,
}

impl Default for PipelineOptions {
    fn default() -> Self {
        PipelineOptions {
            mode: Mode::Sequence,
            job: JobKind::Sequence,
            output_format: Format::Rgba8Srgb,
            output_formats: Vec::new(),
            assume_linear: false,
            rate: 1,
            fps: 25.0,
            emit: None,
            camera: None,
            keep_going: false,
            queue: 3,
            timings: false,
        }
    }
}

impl PipelineOptions {
    fn format_for(&self, number: u64) -> Format {
        usize::try_from(number)
            .ok()
            .and_then(|i| self.output_formats.get(i).copied())
            .unwrap_or(self.output_format)
    }
}

/// A decoded frame on its way to the GPU: position, number, name, frame, decode time.
type Decoded = (
    usize,
    u64,
    String,
    Result<(Image, Vec<(String, Image)>), IoError>,
    Duration,
);

/// A read-back on its way to the encoder.
struct Encoded {
    index: usize,
    number: u64,
    name: String,
    pending: PendingReadback,
    format: Format,
    gpu: Option<Duration>,
    decode: Option<Duration>,
}

/// What the encode thread hands back: busy and wait times, the frames written, the
/// failures, and the read-back wait of the last frame.
struct EncodeResult {
    busy: Duration,
    wait: Duration,
    last_wait: Duration,
    done: Vec<FrameDone>,
    failed: Vec<FrameFailure>,
}

/// Run `effect` over every frame of `source`, writing to `sink`. `stop` ends the run
/// early (Ctrl-C): frames already written stay, frames in flight are finished.
///
/// `Err` when the run cannot go on at all: the device cannot be created, the effect or
/// its shaders are rejected, a thread cannot start, or (sequences) any frame fails.
#[allow(clippy::too_many_arguments)]
pub fn run_frames(
    device: Device,
    effect: &mut Effect,
    mut source: Box<dyn FrameSource>,
    mut sink: Box<dyn FrameSink>,
    opts: &PipelineOptions,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let start = Instant::now();
    let limit = SideLimit::default();
    let device_thread = match &device {
        Device::Engine(e) => {
            limit.set(e.ctx.device.limits().max_texture_dimension_2d);
            None
        }
        Device::Create(adapter) => {
            let adapter = (*adapter).clone();
            let l = limit.clone();
            Some(
                std::thread::Builder::new()
                    .name("fxgraph device".into())
                    .spawn(move || {
                        let t = Instant::now();
                        let r = GpuContext::new(&adapter).map(Engine::new);
                        // A failed device unblocks the decoder (the run ends anyway).
                        l.set(match &r {
                            Ok(e) => e.ctx.device.limits().max_texture_dimension_2d,
                            Err(_) => 0,
                        });
                        r.map(|e| (e, t.elapsed()))
                    })
                    .map_err(|e| RunError::Other(format!("cannot start the device thread: {e}")))?,
            )
        }
    };
    source.set_limit(limit.clone());
    let total = source.frame_count();
    let queue = opts.queue.max(1);
    let stills = opts.mode == Mode::Stills;
    let keep_going = stills && opts.keep_going;
    // Set when the run must end early (a failure without keep_going).
    let halt = Arc::new(AtomicBool::new(false));
    let (dec_tx, dec_rx) = sync_channel::<Decoded>(queue);
    let (enc_tx, enc_rx) = sync_channel::<Encoded>(queue);
    let (halt_d, stop_d) = (halt.clone(), stop.clone());
    let decoder = std::thread::Builder::new()
        .name("fxgraph decode".into())
        .spawn(move || -> Duration {
            let mut busy = Duration::ZERO;
            let mut index = 0usize;
            while !halt_d.load(Ordering::Relaxed) && !stop_d.load(Ordering::Relaxed) {
                let t = Instant::now();
                let Some(f) = source.next_frame() else {
                    break;
                };
                let spent = t.elapsed();
                busy += spent;
                let failed = f.image.is_err();
                let item = f.image.map(|img| (img, f.aux));
                if dec_tx.send((index, f.number, f.name, item, spent)).is_err()
                    || (failed && !keep_going)
                {
                    break;
                }
                index += 1;
            }
            busy
        })
        .map_err(|e| RunError::Other(format!("cannot start the decode thread: {e}")))?;
    let halt_e = halt.clone();
    let encoder = std::thread::Builder::new()
        .name("fxgraph encode".into())
        .spawn(move || {
            let mut r = EncodeResult {
                busy: Duration::ZERO,
                wait: Duration::ZERO,
                last_wait: Duration::ZERO,
                done: Vec::new(),
                failed: Vec::new(),
            };
            for e in enc_rx {
                if !r.failed.is_empty() && !keep_going {
                    continue; // stopped: frames after the failure are not written
                }
                let t = Instant::now();
                let (w, h) = (e.pending.width(), e.pending.height());
                let raw = e.pending.finish().map_err(RunError::from);
                r.last_wait = t.elapsed();
                r.wait += r.last_wait;
                let t = Instant::now();
                let result = raw.and_then(|raw| {
                    let pixels = pixels_from_bytes(raw, e.format)?;
                    sink.write(e.number, w, h, pixels).map_err(RunError::from)
                });
                let spent = t.elapsed();
                r.busy += spent;
                match result {
                    Ok(output) => r.done.push(FrameDone {
                        index: e.index,
                        input: e.name,
                        output,
                        width: w,
                        height: h,
                        decode_ms: e.decode.map(ms),
                        gpu_ms: e.gpu.map(ms),
                        encode_ms: ms(spent),
                    }),
                    Err(err) => {
                        if !keep_going {
                            halt_e.store(true, Ordering::Relaxed);
                        }
                        r.failed.push(FrameFailure::new(e.index, e.name, err));
                    }
                }
            }
            let t = Instant::now();
            if let Err(err) = sink.finish() {
                let n = r.done.len();
                r.failed.push(FrameFailure::new(n, "output", err.into()));
            }
            r.busy += t.elapsed();
            r
        })
        .map_err(|e| RunError::Other(format!("cannot start the encode thread: {e}")))?;

    let mut report = RunReport {
        job: opts.job,
        frames_total: total,
        ..Default::default()
    };
    let mut own_engine = None;
    let engine: Result<&mut Engine, RunError> = match (device, device_thread) {
        (Device::Engine(e), _) => Ok(e),
        (Device::Create(_), Some(h)) => {
            let t = Instant::now();
            let r = h
                .join()
                .map_err(|_| {
                    limit.set(0);
                    RunError::Other("the device thread panicked".into())
                })
                .and_then(|r| r.map_err(RunError::from));
            report.device_wait_ms = ms(t.elapsed());
            match r {
                Ok((e, created)) => {
                    report.device_created_ms = ms(created);
                    Ok(own_engine.insert(e))
                }
                Err(e) => Err(e),
            }
        }
        (Device::Create(_), None) => unreachable!("a device thread for Device::Create"),
    };
    let fatal;
    let mut gpu_busy = Duration::ZERO;
    match engine {
        Err(e) => {
            drop(enc_tx);
            fatal = Some(e);
        }
        Ok(engine) => {
            report.adapter = engine.ctx.info.name.clone();
            report.backend = format!("{:?}", engine.ctx.info.backend);
            let mut gpu = GpuStage {
                engine,
                effect,
                opts,
                report: &mut report,
                enc_tx,
                busy: Duration::ZERO,
                current: None,
                stream: None,
                numbers: VecDeque::new(),
                first_number: None,
            };
            fatal = gpu.run(&dec_rx, &halt, &stop, start, total, &mut progress);
            gpu_busy = gpu.busy;
        }
    }
    // (the stage's sender is dropped with it: the encoder ends after the last frame)
    drop(dec_rx);
    let decode_busy = decoder.join().unwrap_or_default();
    let enc = encoder
        .join()
        .map_err(|_| RunError::Other("the encode thread panicked".into()))?;
    if let Some(e) = fatal {
        return Err(e);
    }
    report.done = enc.done;
    report.failed.extend(enc.failed);
    report.failed.sort_by_key(|f| f.index);
    report.steps.readback_ms = ms(enc.last_wait);
    report.stages.readback_wait_ms = ms(enc.wait);
    report.stages.decode_busy_ms = ms(decode_busy);
    report.stages.gpu_busy_ms = ms(gpu_busy);
    report.stages.encode_busy_ms = ms(enc.busy);
    report.wall_ms = ms(start.elapsed());
    if !stills {
        if let Some(f) = report.failed.drain(..).next() {
            return Err(f.error);
        }
        if report.frames_in == 0 && !report.interrupted {
            return Err(RunError::BadInput(IoError::Decode {
                path: "sequence".into(),
                message: "no frames".into(),
            }));
        }
    }
    Ok(report)
}

/// What the plan of a still and its textures depend on.
#[derive(Clone, PartialEq, Eq)]
struct PlanKey {
    width: u32,
    height: u32,
    input: Format,
    colorspace: ColorSpace,
    output: Format,
    aux: Vec<(String, Format)>,
}

/// The effect prepared for one [`PlanKey`], with its input and output textures.
struct Current {
    key: PlanKey,
    prepared: Prepared,
    input: wgpu::Texture,
    output: wgpu::Texture,
}

/// The GPU thread's state.
struct GpuStage<'a, 'r> {
    engine: &'a mut Engine,
    effect: &'a mut Effect,
    opts: &'a PipelineOptions,
    report: &'r mut RunReport,
    enc_tx: std::sync::mpsc::SyncSender<Encoded>,
    busy: Duration,
    /// Stills: the plan of the last size.
    current: Option<Current>,
    /// Sequences: the stream, the frame numbers pushed and not yet output, the first.
    stream: Option<Stream>,
    numbers: VecDeque<(u64, String)>,
    first_number: Option<u64>,
}

impl GpuStage<'_, '_> {
    /// Take every decoded frame through the GPU; `Some` error ends the run.
    fn run(
        &mut self,
        dec_rx: &std::sync::mpsc::Receiver<Decoded>,
        halt: &AtomicBool,
        stop: &AtomicBool,
        start: Instant,
        total: Option<u64>,
        progress: &mut impl FnMut(Progress),
    ) -> Option<RunError> {
        let stills = self.opts.mode == Mode::Stills;
        for (index, number, name, item, decode_time) in dec_rx {
            if halt.load(Ordering::Relaxed) {
                break;
            }
            self.report.frames_in += 1;
            let (img, aux) = match item {
                Ok(x) => x,
                Err(e) => {
                    if !stills {
                        return Some(e.into());
                    }
                    self.report
                        .failed
                        .push(FrameFailure::new(index, name, e.into()));
                    if !self.opts.keep_going {
                        halt.store(true, Ordering::Relaxed);
                        break;
                    }
                    continue;
                }
            };
            let t = Instant::now();
            let sent = if stills {
                match self.still(&img, &aux, number) {
                    Ok(pending) => {
                        let spent = t.elapsed();
                        self.busy += spent;
                        self.enc_tx
                            .send(Encoded {
                                index,
                                number,
                                name,
                                pending,
                                format: self.opts.format_for(number),
                                gpu: Some(spent),
                                decode: Some(decode_time),
                            })
                            .is_ok()
                    }
                    Err(e @ RunError::Rejected { .. }) => {
                        // The effect or its shaders: every frame would fail the same way.
                        halt.store(true, Ordering::Relaxed);
                        return Some(e);
                    }
                    Err(e) => {
                        self.busy += t.elapsed();
                        // The textures may be in any state after a GPU error: plan afresh.
                        self.current = None;
                        self.report.failed.push(FrameFailure::new(index, name, e));
                        if !self.opts.keep_going {
                            halt.store(true, Ordering::Relaxed);
                            break;
                        }
                        true
                    }
                }
            } else {
                match self.push(&img, number, name).and_then(|()| self.drain()) {
                    Ok(open) => open,
                    Err(e) => return Some(e),
                }
            };
            if !sent {
                break;
            }
            progress(Progress {
                done: self.report.frames_in,
                total,
                elapsed: start.elapsed(),
            });
            if stop.load(Ordering::Relaxed) {
                self.report.interrupted = true;
                break;
            }
        }
        if !stills && !self.report.interrupted && !halt.load(Ordering::Relaxed) {
            if let Some(s) = self.stream.as_mut() {
                s.end();
                if let Err(e) = self.drain() {
                    return Some(e);
                }
            }
        }
        if let Some(s) = &self.stream {
            self.report.passes = s.last_timings.clone();
        }
        None
    }

    fn plan_opts(&self, output: Format) -> PlanOptions {
        PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(output),
        }
    }

    fn note_plan(&mut self, prepared: &Prepared, spent: Duration) {
        self.report.plans += 1;
        self.report.steps.pipeline_ms = ms(spent);
        self.report.memory = MemoryReport {
            peak_bytes: prepared.plan.peak_bytes,
            lower_bound_bytes: prepared.plan.lower_bound_bytes,
            naive_bytes: prepared.plan.naive_bytes,
        };
    }

    /// Run one still (planning again if its size or formats differ from the previous
    /// one's) and start reading its output back.
    fn still(
        &mut self,
        img: &Image,
        aux: &[(String, Image)],
        number: u64,
    ) -> Result<PendingReadback, RunError> {
        let assume_linear = self.opts.assume_linear;
        let (in_format, colorspace) = input_format(img, assume_linear);
        let out_format = self.opts.format_for(number);
        let key = PlanKey {
            width: img.width,
            height: img.height,
            input: in_format,
            colorspace,
            output: out_format,
            aux: aux
                .iter()
                .map(|(n, a)| (n.clone(), input_format(a, assume_linear).0))
                .collect(),
        };
        let ctx = self.engine.ctx.clone();
        let t = Instant::now();
        let mut planning = Duration::ZERO;
        let bytes = image_bytes(img, in_format);
        if self.current.as_ref().is_some_and(|c| c.key == key) {
            let c = self.current.as_ref().expect("checked");
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
            self.current = None;
            let desc = InputDesc {
                width: img.width,
                height: img.height,
                format: in_format,
                colorspace,
                aux: key.aux.clone(),
            };
            // Transient textures come from the engine's pool, kept for the next frame.
            let tp = Instant::now();
            let prepared =
                self.effect
                    .prepare_with(self.engine, &desc, &self.plan_opts(out_format))?;
            planning = tp.elapsed();
            self.note_plan(&prepared, planning);
            let input = ctx.upload_texture(
                "fxgraph input",
                img.width,
                img.height,
                wgpu_format(in_format),
                &bytes,
                wgpu::TextureUsages::empty(),
            )?;
            let out = prepared.plan.output;
            let output = create_output(&ctx, out.width, out.height, out.format);
            self.current = Some(Current {
                key,
                prepared,
                input,
                output,
            });
        }
        let aux_tex = aux
            .iter()
            .map(|(n, a)| {
                let f = input_format(a, assume_linear).0;
                Ok((n.clone(), upload_image(&ctx, &format!("aux {n}"), a, f)?))
            })
            .collect::<Result<Vec<_>, crate::gpu::context::GpuError>>()?;
        self.report.steps.upload_ms = ms(t.elapsed().saturating_sub(planning));
        let t = Instant::now();
        let c = self.current.as_mut().expect("prepared above");
        // Every image is a still of its own: frame 0, as a one-image run.
        c.prepared.frame = 0;
        c.prepared.subframe = 0;
        let mut inputs = FrameInputs::still(&c.input, &c.prepared.plan);
        for (n, tex) in &aux_tex {
            inputs.aux.insert(n.clone(), tex.into());
        }
        inputs.camera = self.opts.camera;
        // The passes and the copy into the read-back buffer: one submission.
        let output = &c.output;
        let (passes, pending) =
            c.prepared
                .run_then(self.engine, &inputs, output, self.opts.timings, |enc| {
                    ctx.encode_readback(enc, output)
                })?;
        self.report.steps.passes_ms = ms(t.elapsed());
        if self.opts.timings {
            self.report.passes = passes;
        }
        Ok(pending)
    }

    /// Push a frame of a sequence into the stream (created for the first frame).
    fn push(&mut self, img: &Image, number: u64, name: String) -> Result<(), RunError> {
        let t = Instant::now();
        if self.stream.is_none() {
            self.first_number = Some(number);
            let (fmt, cs) = input_format(img, self.opts.assume_linear);
            let desc = InputDesc {
                width: img.width,
                height: img.height,
                format: fmt,
                colorspace: cs,
                aux: Vec::new(),
            };
            let mut prepared = self.effect.prepare_with(
                self.engine,
                &desc,
                &self.plan_opts(self.opts.output_format),
            )?;
            self.note_plan(&prepared, t.elapsed());
            prepared.fps = self.opts.fps;
            let mut s = Stream::new(self.engine, prepared, fmt);
            s.rate = self.opts.rate.max(1);
            s.camera = self.opts.camera;
            s.want_timings = self.opts.timings;
            self.report.frames_held_max = 2 * self.opts.queue.max(1) + s.ring_len();
            self.stream = Some(s);
        }
        let s = self.stream.as_mut().expect("stream created");
        let (w, h) = (s.prepared.plan.input.width, s.prepared.plan.input.height);
        if (img.width, img.height) != (w, h) {
            // An input error, not a GPU one: the frames of a sequence have one size.
            return Err(RunError::BadInput(IoError::Decode {
                path: name.into(),
                message: format!(
                    "the frame is {}x{}, the sequence started at {w}x{h} (frame {}): the frames of a sequence must have one size",
                    img.width,
                    img.height,
                    self.first_number.unwrap_or(0)
                ),
            }));
        }
        self.numbers.push_back((number, name));
        s.push_image(self.engine, img)?;
        self.busy += t.elapsed();
        Ok(())
    }

    /// Send the stream's ready outputs to the encoder; false when the encoder is gone.
    fn drain(&mut self) -> Result<bool, RunError> {
        let first = self.first_number.unwrap_or(0);
        let Some(stream) = self.stream.as_mut() else {
            return Ok(true);
        };
        loop {
            let t = Instant::now();
            // The frame's passes and the copy of its output: one submission.
            let Some((out, pending)) = stream.next_read_back(self.engine)? else {
                self.busy += t.elapsed();
                return Ok(true);
            };
            self.busy += t.elapsed();
            let rate = stream.rate as u64;
            let (input_index, sub) = (out / rate, out % rate);
            let (input_number, name) = self
                .numbers
                .get(input_index as usize)
                .cloned()
                .unwrap_or((first + input_index, String::new()));
            let keep = self
                .opts
                .emit
                .is_none_or(|(lo, hi)| input_number >= lo && input_number <= hi);
            if !keep {
                continue;
            }
            let number = if rate == 1 {
                input_number
            } else {
                first * rate + input_index * rate + sub
            };
            let e = Encoded {
                index: out as usize,
                number,
                name,
                pending,
                format: stream.prepared.plan.output.format,
                gpu: None,
                decode: None,
            };
            if self.enc_tx.send(e).is_err() {
                return Ok(false);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SideLimit;

    #[test]
    fn side_limit_waits_for_the_device_only_above_what_every_device_takes() {
        let limit = SideLimit::default();
        // Every device takes 8192 px per side: answered before the device exists.
        assert_eq!(limit.check(8192, 100), Ok(()));
        let l = limit.clone();
        let waiter = std::thread::spawn(move || (l.check(10000, 10), l.check(20000, 10)));
        std::thread::sleep(std::time::Duration::from_millis(20));
        limit.set(16384);
        assert_eq!(waiter.join().unwrap(), (Ok(()), Err(16384)));
        // The io layer's cap bounds any device's limit.
        assert_eq!(SideLimit::known(1 << 20).check(40000, 1), Err(32768));
    }
}
