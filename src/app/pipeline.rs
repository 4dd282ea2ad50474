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
pub use super::frames::{FrameSink, FrameSource, OutputFrame, Picture, SideLimit, SourceFrame};
use super::gpu_stage::GpuStage;
pub use super::pipeline_options::{Mode, PipelineOptions};
use super::planes::PlaneRoute;
use super::report::{ms, FrameDone, FrameFailure, Progress, RunReport};
use super::stage_messages::{Decoded, Encoded, Readback};
use crate::gpu::context::{AdapterChoice, GpuContext, GpuError};
use crate::gpu::executor::Engine;
use crate::gpu::transfer::pixels_from_bytes;
use crate::io::IoError;
use crate::script::types::Format;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The device of a run.
pub enum Device<'a> {
    /// The caller's engine (its device, pipelines and pools are reused).
    Engine(&'a mut Engine),
    /// Create one (on a thread, while the first frames are decoded); it is dropped
    /// when the run ends.
    Create(&'a AdapterChoice),
    /// Create one as [`Device::Create`] does and leave it in the caller's slot
    /// (replacing what it held) when the run ends, whether the run succeeded or
    /// not, so that the caller decides when it is dropped: a program about to exit
    /// may skip destroying it (the driver's teardown).
    CreateInto(&'a AdapterChoice, &'a mut Option<Engine>),
}

impl<'a> Device<'a> {
    /// The engine `kept` holds; when it holds none, one the run creates and leaves in
    /// `kept` ([`Device::CreateInto`]).
    pub fn kept(kept: &'a mut Option<Engine>, adapter: &'a AdapterChoice) -> Device<'a> {
        if kept.is_some() {
            Device::Engine(kept.as_mut().expect("checked"))
        } else {
            Device::CreateInto(adapter, kept)
        }
    }
}

/// What the encode thread hands back: busy and wait times, the frames written, the
/// failures, and the read-back wait of the last frame.
pub(super) struct EncodeResult {
    pub(super) busy: Duration,
    pub(super) wait: Duration,
    pub(super) last_wait: Duration,
    pub(super) done: Vec<FrameDone>,
    pub(super) failed: Vec<FrameFailure>,
}

/// The encode thread: finishes each read-back of `enc_rx`, writes it to `sink`
/// and records it; a failed write sets `halt` unless `keep_going` (frames after
/// it are then not written). Ends when `enc_rx` is closed: with `sink.finish` when
/// `complete` was set before (every frame went through) and no write failed,
/// else with `sink.abort` (a partial output is discarded).
pub(super) fn spawn_encoder(
    mut sink: Box<dyn FrameSink>,
    enc_rx: std::sync::mpsc::Receiver<Encoded>,
    keep_going: bool,
    halt_e: Arc<AtomicBool>,
    complete_e: Arc<AtomicBool>,
) -> Result<std::thread::JoinHandle<EncodeResult>, RunError> {
    std::thread::Builder::new()
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
                let (w, h) = e.pending.size();
                let (result, wait, t) = write_one(&mut *sink, e.pending, e.number, e.format);
                r.last_wait = wait;
                r.wait += wait;
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
            // Complete: every frame read went through and was written, not stopped.
            if complete_e.load(Ordering::SeqCst) && r.failed.is_empty() {
                if let Err(err) = sink.finish() {
                    let n = r.done.len();
                    r.failed.push(FrameFailure::new(n, "output", err.into()));
                }
            } else {
                sink.abort();
            }
            r.busy += t.elapsed();
            r
        })
        .map_err(|e| RunError::Other(format!("cannot start the encode thread: {e}")))
}

/// Finish a read-back and write it to `sink`: the result, the time waited for the
/// read-back, and when the writing started.
fn write_one(
    sink: &mut dyn FrameSink,
    pending: Readback,
    number: u64,
    format: Format,
) -> (Result<String, RunError>, Duration, Instant) {
    let t = Instant::now();
    let (width, height) = pending.size();
    let raw = match pending {
        Readback::Texture(p) => p.finish().map(|raw| (raw, false)),
        Readback::Planes(p, ..) => p.finish().map(|raw| (raw, true)),
    };
    let wait = t.elapsed();
    let t = Instant::now();
    let result = raw.map_err(RunError::from).and_then(|(raw, planes)| {
        if planes {
            return sink
                .write_planes(number, width, height, raw)
                .map_err(RunError::from);
        }
        let pixels = pixels_from_bytes(raw, format)?;
        sink.write(OutputFrame {
            number,
            width,
            height,
            pixels,
        })
        .map_err(RunError::from)
    });
    (result, wait, t)
}

/// Run `effect` over every frame of `source`, writing to `sink`. `stop` ends the run
/// early (Ctrl-C): frames already written stay, frames in flight are finished.
///
/// `Err` when the run cannot go on at all: the device cannot be created, the effect or
/// A viewport (`fxrun --size` with an input) that no pass scales from would be
/// ignored: refused before any frame is read.
fn check_viewport(effect: &Effect, opts: &PipelineOptions) -> Result<(), RunError> {
    if opts.viewport.is_some() && !effect.graph.scales_from_viewport() {
        return Err(RunError::Rejected {
            rendered: "--size with -i INPUT sets the viewport, the size passes scale from as \
                       OUT.RELATIVE_TO = VIEWPORT (a slang preset's viewport); no pass of these \
                       effects does, so the output has the size their passes give it \
                       (OUT.SIZE, OUT.SCALE)"
                .into(),
        });
    }
    Ok(())
}

/// its shaders are rejected, a thread cannot start, or (sequences) any frame fails.
#[allow(clippy::too_many_arguments)]
pub fn run_frames(
    device: Device,
    effect: &mut Effect,
    mut source: Box<dyn FrameSource>,
    sink: Box<dyn FrameSink>,
    opts: &PipelineOptions,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    check_viewport(effect, opts)?;
    let start = Instant::now();
    let (device, keep) = match device {
        Device::CreateInto(adapter, slot) => (Device::Create(adapter), Some(slot)),
        other => (other, None),
    };
    let limit = SideLimit::default();
    // Y'CbCr planes go to the GPU for sequences, as `opts.ycbcr` says for the device.
    let route = PlaneRoute::default();
    let device_thread = start_device(&device, opts, &limit, &route)?;
    source.set_limit(limit.clone());
    source.set_plane_route(route.clone());
    let total = source.frame_count();
    let queue = opts.queue.max(1);
    let stills = opts.mode == Mode::Stills;
    let keep_going = stills && opts.keep_going;
    // Set when the run must end early (a failure without keep_going).
    let halt = Arc::new(AtomicBool::new(false));
    let (dec_tx, dec_rx) = sync_channel::<Decoded>(queue);
    let (enc_tx, enc_rx) = sync_channel::<Encoded>(queue);
    let decoder = spawn_decoder(source, dec_tx, keep_going, halt.clone(), stop.clone())?;
    // Set by this thread once the GPU stage has ended (before the encoder sees the
    // end of its queue): whether the run completed, so the sink can make its output
    // final (`finish`) or discard it (`abort`).
    let complete = Arc::new(AtomicBool::new(false));
    // What a y4m sink writes, for planes made on the GPU (used if the route says so).
    let plane_output = sink.plane_output();
    let encoder = spawn_encoder(sink, enc_rx, keep_going, halt.clone(), complete.clone())?;
    let mut report = RunReport {
        job: opts.job,
        frames_total: total,
        frames_held_max: frames_held(queue),
        ..Default::default()
    };
    let mut own_engine = None;
    if device_thread.is_some() {
        // While the device is created: the shaders need none.
        effect.preload_shaders();
    }
    let engine = engine_of(
        device,
        device_thread,
        (&limit, &route),
        &mut report,
        &mut own_engine,
    );
    let (fatal, gpu_busy) = match engine {
        Err(e) => {
            drop(enc_tx);
            (Some(e), Duration::ZERO)
        }
        Ok(engine) => {
            report.adapter = engine.ctx.info.name.clone();
            report.backend = format!("{:?}", engine.ctx.info.backend);
            let mut gpu = GpuStage::new(engine, effect, opts, &mut report, enc_tx);
            if route.decided() == Some(true) {
                gpu.offer_planes(plane_output);
            }
            let flags = (&*halt, &*stop, &*complete);
            let fatal = gpu.run_to_end(&dec_rx, flags, (start, total), &mut progress);
            (fatal, gpu.busy)
        }
    };
    // (the stage's sender is dropped with it: the encoder ends after the last frame)
    drop(dec_rx);
    if let Some(e) = &own_engine {
        super::pipeline_cache::save(&e.ctx);
    }
    if let (Some(slot), Some(e)) = (keep, own_engine.take()) {
        *slot = Some(e);
    }
    let decode_busy = decoder.join().unwrap_or_default();
    let enc = encoder
        .join()
        .map_err(|_| RunError::Other("the encode thread panicked".into()))?;
    if let Some(e) = fatal {
        return Err(e);
    }
    report.stages.decode_busy_ms = ms(decode_busy);
    report.stages.gpu_busy_ms = ms(gpu_busy);
    finish_report(report, enc, start, stills)
}

/// The most frames a run of stills holds at once with `queue`: decoded frames waiting
/// for the GPU, the one on the GPU, read-backs waiting for the encoder, the one being
/// encoded (sequences add their ring: set when the stream is made).
fn frames_held(queue: usize) -> usize {
    2 * queue + 2
}

/// The thread that creates the device of [`Device::Create`], returning the engine and
/// the time it took.
type DeviceThread = std::thread::JoinHandle<Result<(Engine, Duration), GpuError>>;

/// Sets the side limit and the plane route from the caller's engine, or starts the
/// thread that creates the device and sets them once it exists.
fn start_device(
    device: &Device,
    opts: &PipelineOptions,
    limit: &SideLimit,
    route: &PlaneRoute,
) -> Result<Option<DeviceThread>, RunError> {
    let (ycbcr, sequence) = (opts.ycbcr, opts.mode == Mode::Sequence);
    match device {
        Device::Engine(e) => {
            limit.set(e.ctx.device.limits().max_texture_dimension_2d);
            route.set(sequence && ycbcr.wants_gpu(e.ctx.info.device_type));
            Ok(None)
        }
        Device::Create(adapter) | Device::CreateInto(adapter, _) => {
            let adapter = (*adapter).clone();
            let (l, route) = (limit.clone(), route.clone());
            Ok(Some(
                std::thread::Builder::new()
                    .name("fxgraph device".into())
                    .spawn(move || {
                        let t = Instant::now();
                        let r = GpuContext::new(&adapter).map(|mut ctx| {
                            super::pipeline_cache::attach(&mut ctx);
                            Engine::new(ctx)
                        });
                        // A failed device unblocks the decoder (the run ends anyway).
                        l.set(match &r {
                            Ok(e) => e.ctx.device.limits().max_texture_dimension_2d,
                            Err(_) => 0,
                        });
                        route
                            .set(r.as_ref().is_ok_and(|e| {
                                sequence && ycbcr.wants_gpu(e.ctx.info.device_type)
                            }));
                        r.map(|e| (e, t.elapsed()))
                    })
                    .map_err(|e| RunError::Other(format!("cannot start the device thread: {e}")))?,
            ))
        }
    }
}

/// The decode thread: reads frames from `source` into `dec_tx` until the source ends,
/// `halt` or `stop` is set, or (without `keep_going`) a frame fails to decode; hands
/// back its busy time.
fn spawn_decoder(
    mut source: Box<dyn FrameSource>,
    dec_tx: std::sync::mpsc::SyncSender<Decoded>,
    keep_going: bool,
    halt_d: Arc<AtomicBool>,
    stop_d: Arc<AtomicBool>,
) -> Result<std::thread::JoinHandle<Duration>, RunError> {
    std::thread::Builder::new()
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
        .map_err(|e| RunError::Other(format!("cannot start the decode thread: {e}")))
}

/// The engine of the run: the caller's, or the one the device thread created (kept in
/// `own_engine`; the wait for it and its creation time go to `report`). A device that
/// failed unblocks the limit and the route.
fn engine_of<'a>(
    device: Device<'a>,
    device_thread: Option<DeviceThread>,
    (limit, route): (&SideLimit, &PlaneRoute),
    report: &mut RunReport,
    own_engine: &'a mut Option<Engine>,
) -> Result<&'a mut Engine, RunError> {
    match (device, device_thread) {
        (Device::Engine(e), _) => Ok(e),
        (Device::Create(_) | Device::CreateInto(..), Some(h)) => {
            let t = Instant::now();
            let r = h
                .join()
                .map_err(|_| {
                    limit.set(0);
                    route.set(false);
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
        (Device::Create(_) | Device::CreateInto(..), None) => {
            unreachable!("a device thread for Device::Create")
        }
    }
}

/// The report of a finished run, with what the encoder wrote; `Err` for a sequence
/// with a failed frame or no frame at all.
fn finish_report(
    mut report: RunReport,
    enc: EncodeResult,
    start: Instant,
    stills: bool,
) -> Result<RunReport, RunError> {
    report.done = enc.done;
    report.failed.extend(enc.failed);
    report.failed.sort_by_key(|f| f.index);
    report.steps.readback_ms = ms(enc.last_wait);
    report.stages.readback_wait_ms = ms(enc.wait);
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
