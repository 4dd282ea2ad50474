//! Frame sequences through an effect, pipelined: a decode thread, the GPU (this
//! thread) and an encode thread, connected by bounded queues, so decoding the next
//! frames and encoding the previous ones overlap the GPU work on the current one.
//!
//! Memory is bounded for any sequence length: at most `queue` decoded frames wait
//! for the GPU, the stream holds `history + latency + 1` input textures, the plan's
//! transient textures (its `Pool` peak) and feedback rings, and at most `queue`
//! read-back frames wait for the encoder.

use super::effect::Effect;
use super::error::RunError;
use super::report::{ms, FrameDone, JobKind, MemoryReport, Progress, RunReport};
use crate::gpu::context::PendingReadback;
use crate::gpu::executor::{CameraStd, Engine};
use crate::gpu::stream::Stream;
use crate::gpu::transfer::{input_format, pixels_from_bytes};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{Image, IoError, Pixels};
use crate::script::types::Format;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where frames come from (runs on the decode thread).
pub trait FrameSource: Send {
    /// Number of frames, if known (for the progress bar).
    fn frame_count(&self) -> Option<u64>;
    /// The next frame and its frame number, or `None` at the end.
    fn next_frame(&mut self) -> Result<Option<(u64, Image)>, IoError>;
    /// The largest width or height the device takes: a source that can read an image's
    /// size before decoding it refuses larger ones (naming the file) without decoding.
    fn set_max_side(&mut self, _max: u32) {}
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
        }
    }
}

type Decoded = Result<(u64, Image), IoError>;
type Encoded = (u64, PendingReadback, Format);

/// Run `effect` over every frame of `source`, writing to `sink`. `stop` ends the
/// run early (Ctrl-C): frames already written stay, frames in flight are finished.
#[allow(clippy::too_many_arguments)]
pub fn run_sequence(
    engine: &mut Engine,
    effect: &mut Effect,
    mut source: Box<dyn FrameSource>,
    mut sink: Box<dyn FrameSink>,
    opts: &SequenceOptions,
    camera: Option<CameraStd>,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let start = Instant::now();
    source.set_max_side(engine.ctx.device.limits().max_texture_dimension_2d);
    let total = source.frame_count();
    let queue = opts.queue.max(1);
    let (dec_tx, dec_rx): (SyncSender<Decoded>, Receiver<Decoded>) = sync_channel(queue);
    let (enc_tx, enc_rx): (SyncSender<Encoded>, Receiver<Encoded>) = sync_channel(queue);
    let stop_decode = stop.clone();
    let decoder = std::thread::Builder::new()
        .name("fxgraph decode".into())
        .spawn(move || -> Duration {
            let mut busy = Duration::ZERO;
            loop {
                if stop_decode.load(Ordering::Relaxed) {
                    break;
                }
                let t = Instant::now();
                let item = source.next_frame();
                busy += t.elapsed();
                match item {
                    Ok(Some(f)) => {
                        if dec_tx.send(Ok(f)).is_err() {
                            break;
                        }
                    }
                    Ok(None) => break,
                    Err(e) => {
                        let _ = dec_tx.send(Err(e));
                        break;
                    }
                }
            }
            busy
        })
        .map_err(|e| RunError::Other(format!("cannot start the decode thread: {e}")))?;
    let encoder = std::thread::Builder::new()
        .name("fxgraph encode".into())
        .spawn(
            move || -> (Duration, Duration, Result<Vec<FrameDone>, RunError>) {
                // `wait`: blocked until the GPU finished the frame; `busy`: converting and
                // writing it.
                let mut busy = Duration::ZERO;
                let mut wait = Duration::ZERO;
                let mut written = Vec::new();
                for (number, pending, format) in enc_rx {
                    let t = Instant::now();
                    let (w, h) = (pending.width(), pending.height());
                    let raw = pending.finish().map_err(RunError::from);
                    wait += t.elapsed();
                    let t = Instant::now();
                    let result = raw.and_then(|raw| {
                        let pixels = pixels_from_bytes(raw, format)?;
                        sink.write(number, w, h, pixels).map_err(RunError::from)
                    });
                    let spent = t.elapsed();
                    busy += spent;
                    match result {
                        Ok(output) => written.push(FrameDone {
                            index: written.len(),
                            input: format!("frame {number}"),
                            output,
                            width: w,
                            height: h,
                            decode_ms: None,
                            gpu_ms: None,
                            encode_ms: ms(spent),
                        }),
                        Err(e) => return (busy, wait, Err(e)),
                    }
                }
                let t = Instant::now();
                let r = sink.finish().map_err(RunError::from).map(|_| written);
                busy += t.elapsed();
                (busy, wait, r)
            },
        )
        .map_err(|e| RunError::Other(format!("cannot start the encode thread: {e}")))?;

    let mut report = RunReport {
        job: JobKind::Sequence,
        adapter: engine.ctx.info.name.clone(),
        backend: format!("{:?}", engine.ctx.info.backend),
        frames_total: total,
        ..Default::default()
    };
    let mut gpu_busy = Duration::ZERO;
    let mut stream: Option<Stream> = None;
    let mut numbers: VecDeque<u64> = VecDeque::new();
    let mut first_number = None;
    let mut failure: Option<RunError> = None;
    let mut emitted = 0u64;
    // Sends ready outputs to the encoder; returns false when the encoder is gone.
    let drain = |engine: &mut Engine,
                 stream: &mut Stream,
                 numbers: &mut VecDeque<u64>,
                 first: u64,
                 gpu_busy: &mut Duration,
                 emitted: &mut u64|
     -> Result<bool, RunError> {
        loop {
            let t = Instant::now();
            // The frame's passes and the copy of its output for the encoder thread:
            // one submission.
            let Some((out, pending)) = stream.next_read_back(engine)? else {
                *gpu_busy += t.elapsed();
                return Ok(true);
            };
            let rate = stream.rate as u64;
            let input_index = out / rate;
            let sub = out % rate;
            let input_number = numbers
                .get(input_index as usize)
                .copied()
                .unwrap_or(first + input_index);
            *gpu_busy += t.elapsed();
            let keep = opts
                .emit
                .is_none_or(|(lo, hi)| input_number >= lo && input_number <= hi);
            if keep {
                let number = if rate == 1 {
                    input_number
                } else {
                    first * rate + input_index * rate + sub
                };
                if enc_tx
                    .send((number, pending, stream.prepared.plan.output.format))
                    .is_err()
                {
                    return Ok(false);
                }
                *emitted += 1;
            }
        }
    };
    for item in &dec_rx {
        let (number, img) = match item {
            Ok(x) => x,
            Err(e) => {
                failure = Some(e.into());
                break;
            }
        };
        let t = Instant::now();
        if stream.is_none() {
            first_number = Some(number);
            let (fmt, cs) = input_format(&img, opts.assume_linear);
            let desc = InputDesc {
                width: img.width,
                height: img.height,
                format: fmt,
                colorspace: cs,
                aux: Vec::new(),
            };
            let plan_opts = PlanOptions {
                policy: ReusePolicy::Pool,
                output_format: Some(opts.output_format),
            };
            let mut prepared = match effect.prepare_with(engine, &desc, &plan_opts) {
                Ok(p) => p,
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            };
            prepared.fps = opts.fps;
            report.plans += 1;
            report.memory = MemoryReport {
                peak_bytes: prepared.plan.peak_bytes,
                lower_bound_bytes: prepared.plan.lower_bound_bytes,
                naive_bytes: prepared.plan.naive_bytes,
            };
            let mut s = Stream::new(engine, prepared, fmt);
            s.rate = opts.rate.max(1);
            s.camera = camera;
            s.want_timings = opts.timings;
            report.frames_held_max = 2 * queue + s.ring_len();
            stream = Some(s);
        }
        let s = stream.as_mut().expect("stream created");
        let (w, h) = (s.prepared.plan.input.width, s.prepared.plan.input.height);
        if (img.width, img.height) != (w, h) {
            // An input error, not a GPU one: the frames of a sequence have one size.
            failure = Some(RunError::BadInput(IoError::Decode {
                path: format!("frame {number}").into(),
                message: format!(
                    "the frame is {}x{}, the sequence started at {w}x{h} (frame {}): the frames of a sequence must have one size",
                    img.width,
                    img.height,
                    first_number.unwrap_or(0)
                ),
            }));
            break;
        }
        numbers.push_back(number);
        if let Err(e) = s.push_image(engine, &img) {
            failure = Some(e.into());
            break;
        }
        report.frames_in += 1;
        gpu_busy += t.elapsed();
        match drain(
            engine,
            s,
            &mut numbers,
            first_number.unwrap_or(0),
            &mut gpu_busy,
            &mut emitted,
        ) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                failure = Some(e);
                break;
            }
        }
        progress(Progress {
            done: report.frames_in,
            total,
            elapsed: start.elapsed(),
        });
        if stop.load(Ordering::Relaxed) {
            report.interrupted = true;
            break;
        }
    }
    if failure.is_none() && !report.interrupted {
        if let Some(s) = stream.as_mut() {
            s.end();
            if let Err(e) = drain(
                engine,
                s,
                &mut numbers,
                first_number.unwrap_or(0),
                &mut gpu_busy,
                &mut emitted,
            ) {
                failure = Some(e);
            }
        }
    }
    if let Some(s) = &stream {
        report.passes = s.last_timings.clone();
    }
    drop(enc_tx);
    drop(dec_rx);
    let decode_busy = decoder.join().unwrap_or_default();
    let (encode_busy, readback_wait, written) = encoder.join().unwrap_or((
        Duration::ZERO,
        Duration::ZERO,
        Err(RunError::Other("the encode thread panicked".into())),
    ));
    report.stages.readback_wait_ms = ms(readback_wait);
    report.stages.decode_busy_ms = ms(decode_busy);
    report.stages.gpu_busy_ms = ms(gpu_busy);
    report.stages.encode_busy_ms = ms(encode_busy);
    report.wall_ms = ms(start.elapsed());
    if let Some(e) = failure {
        return Err(e);
    }
    report.done = written?;
    if report.frames_in == 0 && !report.interrupted {
        return Err(RunError::BadInput(IoError::Decode {
            path: "sequence".into(),
            message: "no frames".into(),
        }));
    }
    Ok(report)
}
