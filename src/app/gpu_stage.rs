//! The GPU stage of the pipeline ([`super::pipeline`]): stills (planned again when
//! the size or a format changes) or a sequence through a [`Stream`]; every frame one
//! submission (its passes and the copy of its output for the encoder).

use super::effect::Effect;
use super::error::RunError;
use super::frames::Picture;
use super::gpu_planes::{picture_format, PlaneStage};
use super::pipeline_options::{Mode, PipelineOptions};
use super::report::{ms, FrameFailure, MemoryReport, Progress, RunReport};
use super::stage_messages::{Decoded, Encoded, Readback};
use crate::gpu::context::PendingReadback;
use crate::gpu::executor::{wgpu_format, Engine, FrameInputs, Prepared};
use crate::gpu::stream::Stream;
use crate::gpu::transfer::{create_output, image_bytes, input_format, upload_image};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::io::{Image, IoError};
use crate::script::types::{ColorSpace, Format};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// What the plan of a still and its textures depend on.
#[derive(Clone, PartialEq, Eq)]
struct PlanKey {
    width: u32,
    height: u32,
    input: Format,
    colorspace: ColorSpace,
    output: Format,
    aux: Vec<(String, Format)>,
    /// Each auxiliary image's own size (it may differ from the input's).
    aux_sizes: Vec<(String, (u32, u32))>,
}

/// The effect prepared for one [`PlanKey`], with its input and output textures.
struct Current {
    key: PlanKey,
    prepared: Prepared,
    input: wgpu::Texture,
    output: wgpu::Texture,
}

/// What became of a decoded frame in the GPU stage: the run goes on (`Next`, after its
/// progress; `Skip`, without), stops there, or fails.
enum Step {
    Next,
    Skip,
    Stop,
    Fail(RunError),
}

/// A decoded still: its index in the run, its number and name, its decoding time.
struct StillFrame {
    index: usize,
    number: u64,
    name: String,
    decode_time: Duration,
}

/// The GPU thread's state.
pub(super) struct GpuStage<'a, 'r> {
    engine: &'a mut Engine,
    effect: &'a mut Effect,
    opts: &'a PipelineOptions,
    report: &'r mut RunReport,
    enc_tx: std::sync::mpsc::SyncSender<Encoded>,
    /// Time this stage was busy.
    pub(super) busy: Duration,
    /// Stills: the plan of the last size.
    current: Option<Current>,
    /// Sequences: the stream, the numbers and names of the frames pushed and not yet
    /// output (all their subframes), the first number.
    stream: Option<Stream>,
    numbers: VecDeque<(u64, String)>,
    first_number: Option<u64>,
    /// Sequences: the Y'CbCr conversions on the device.
    planes: PlaneStage,
}

impl<'a, 'r> GpuStage<'a, 'r> {
    pub(super) fn new(
        engine: &'a mut Engine,
        effect: &'a mut Effect,
        opts: &'a PipelineOptions,
        report: &'r mut RunReport,
        enc_tx: std::sync::mpsc::SyncSender<Encoded>,
    ) -> Self {
        GpuStage {
            engine,
            effect,
            opts,
            report,
            enc_tx,
            busy: Duration::ZERO,
            current: None,
            stream: None,
            numbers: VecDeque::new(),
            first_number: None,
            planes: PlaneStage::default(),
        }
    }

    /// A y4m sink's header and conversion: its planes are made on the GPU where it
    /// can.
    pub(super) fn offer_planes(
        &mut self,
        offer: Option<(crate::io::y4m::Y4mHeader, crate::io::y4m::YuvConversion)>,
    ) {
        self.planes.offer(offer);
    }

    /// Whether every frame so far went through: no failure recorded, not interrupted.
    fn completed(&self) -> bool {
        !self.report.interrupted && self.report.failed.is_empty()
    }

    /// Record that the run was stopped (Ctrl-C) before its input ended.
    fn mark_interrupted(&mut self) {
        self.report.interrupted = true;
    }

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
            let step = match item {
                Err(e) => self.decode_failed(index, name, e, halt),
                Ok((img, aux)) if stills => {
                    let frame = StillFrame {
                        index,
                        number,
                        name,
                        decode_time,
                    };
                    self.still_frame(frame, img, &aux, halt)
                }
                Ok((img, aux)) => match self
                    .push(img, &aux, number, name)
                    .and_then(|()| self.drain())
                {
                    Ok(true) => Step::Next,
                    Ok(false) => Step::Stop,
                    Err(e) => Step::Fail(e),
                },
            };
            match step {
                Step::Next => {}
                Step::Skip => continue,
                Step::Stop => break,
                Step::Fail(e) => return Some(e),
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
            if let Err(e) = self.end_stream() {
                return Some(e);
            }
        }
        if let Some(s) = &self.stream {
            self.report.passes = s.median_timings();
        }
        None
    }

    /// [`Self::run`], then: a stop seen by the decoder alone (between two frames) ended
    /// the input early, and the run was interrupted all the same; `complete` says
    /// whether the run completed (no error, every frame through, not halted).
    pub(super) fn run_to_end(
        &mut self,
        dec_rx: &std::sync::mpsc::Receiver<Decoded>,
        (halt, stop, complete): (&AtomicBool, &AtomicBool, &AtomicBool),
        (start, total): (Instant, Option<u64>),
        progress: &mut impl FnMut(Progress),
    ) -> Option<RunError> {
        let fatal = self.run(dec_rx, halt, stop, start, total, progress);
        if stop.load(Ordering::SeqCst) {
            self.mark_interrupted();
        }
        let done = fatal.is_none() && self.completed() && !halt.load(Ordering::Relaxed);
        complete.store(done, Ordering::SeqCst);
        fatal
    }

    /// A frame that could not be decoded: the end of a sequence; for stills, a failure
    /// recorded, the run halted unless `keep_going`.
    fn decode_failed(&mut self, index: usize, name: String, e: IoError, halt: &AtomicBool) -> Step {
        if self.opts.mode != Mode::Stills {
            return Step::Fail(e.into());
        }
        self.report
            .failed
            .push(FrameFailure::new(index, name, e.into()));
        if !self.opts.keep_going {
            halt.store(true, Ordering::Relaxed);
            return Step::Stop;
        }
        Step::Skip
    }

    /// Runs one still and sends its read-back to the encoder. A rejected effect ends
    /// the run (every frame would fail the same way); another failure is recorded and
    /// halts the run unless `keep_going`.
    fn still_frame(
        &mut self,
        frame: StillFrame,
        img: Picture,
        aux: &[(String, Image)],
        halt: &AtomicBool,
    ) -> Step {
        let StillFrame {
            index,
            number,
            name,
            decode_time,
        } = frame;
        let t = Instant::now();
        let still = img
            .into_image(&name)
            .map_err(RunError::from)
            .and_then(|img| self.still(&img, aux, number));
        match still {
            Ok(pending) => {
                let pending = Readback::Texture(pending);
                let spent = t.elapsed();
                self.busy += spent;
                let sent = self.enc_tx.send(Encoded {
                    index,
                    number,
                    name,
                    pending,
                    format: self.opts.format_for(number),
                    gpu: Some(spent),
                    decode: Some(decode_time),
                });
                if sent.is_ok() {
                    Step::Next
                } else {
                    Step::Stop
                }
            }
            Err(e @ RunError::Rejected { .. }) => {
                // The effect or its shaders: every frame would fail the same way.
                halt.store(true, Ordering::Relaxed);
                Step::Fail(e)
            }
            Err(e) => {
                self.busy += t.elapsed();
                // The textures may be in any state after a GPU error: plan afresh.
                self.current = None;
                self.report.failed.push(FrameFailure::new(index, name, e));
                if !self.opts.keep_going {
                    halt.store(true, Ordering::Relaxed);
                    return Step::Stop;
                }
                Step::Next
            }
        }
    }

    /// The input of a sequence has ended: the stream outputs the frames it still holds.
    fn end_stream(&mut self) -> Result<(), RunError> {
        if let Some(s) = self.stream.as_mut() {
            s.end();
            self.drain()?;
        }
        Ok(())
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
        self.report.memory = MemoryReport::of(&prepared.plan);
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
        let (aux_formats, aux_sizes) = aux_plan(aux, assume_linear);
        let key = PlanKey {
            width: img.width,
            height: img.height,
            input: in_format,
            colorspace,
            output: self.opts.format_for(number),
            aux: aux_formats,
            aux_sizes,
        };
        let ctx = self.engine.ctx.clone();
        let t = Instant::now();
        let bytes = image_bytes(img, in_format);
        let planning = self.upload_input(img, key, &bytes)?;
        let aux_tex = aux
            .iter()
            .map(|(n, a)| {
                let f = input_format(a, assume_linear).0;
                Ok((n.clone(), upload_image(&ctx, &format!("aux {n}"), a, f)?))
            })
            .collect::<Result<Vec<_>, crate::gpu::context::GpuError>>()?;
        self.report.steps.upload_ms = ms(t.elapsed().saturating_sub(planning));
        self.run_current(&aux_tex)
    }

    /// Writes the input `bytes` of `img` into the current plan's input texture when
    /// `key` is the current plan's; else plans afresh for `key` (the previous size's
    /// textures freed first) and uploads them into a new input. The time spent
    /// planning.
    fn upload_input(
        &mut self,
        img: &Image,
        key: PlanKey,
        bytes: &[u8],
    ) -> Result<Duration, RunError> {
        let ctx = self.engine.ctx.clone();
        if let Some(c) = self.current.as_ref().filter(|c| c.key == key) {
            let texel = (bytes.len() / (img.width as usize * img.height as usize)) as u32;
            ctx.queue.write_texture(
                c.input.as_image_copy(),
                bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(img.width * texel),
                    rows_per_image: None,
                },
                c.input.size(),
            );
            return Ok(Duration::ZERO);
        }
        // Free the previous size's textures before allocating the new ones.
        self.current = None;
        let desc = InputDesc {
            width: img.width,
            height: img.height,
            format: key.input,
            colorspace: key.colorspace,
            aux: key.aux.clone(),
            aux_sizes: key.aux_sizes.clone(),
            viewport: self.opts.viewport,
        };
        // Transient textures come from the engine's pool, kept for the next frame.
        let tp = Instant::now();
        let prepared = self
            .effect
            .prepare_with(self.engine, &desc, &self.plan_opts(key.output))?;
        let planning = tp.elapsed();
        self.note_plan(&prepared, planning);
        let input = ctx.upload_texture(
            "fxgraph input",
            img.width,
            img.height,
            wgpu_format(key.input),
            bytes,
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
        Ok(planning)
    }

    /// Runs the current plan's passes as a still (frame 0) over its input and `aux`,
    /// and the copy of its output into a read-back buffer: one submission.
    fn run_current(
        &mut self,
        aux_tex: &[(String, wgpu::Texture)],
    ) -> Result<PendingReadback, RunError> {
        let ctx = self.engine.ctx.clone();
        let t = Instant::now();
        let c = self.current.as_mut().expect("prepared above");
        // Every image is a still of its own: frame 0, as a one-image run.
        c.prepared.frame = 0;
        c.prepared.subframe = 0;
        let mut inputs = FrameInputs::still(&c.input, &c.prepared.plan);
        for (n, tex) in aux_tex {
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

    /// Push a frame of a sequence into the stream (created for the first frame,
    /// with the auxiliary images `aux` of the first frame for the whole sequence).
    fn push(
        &mut self,
        img: Picture,
        aux: &[(String, Image)],
        number: u64,
        name: String,
    ) -> Result<(), RunError> {
        let t = Instant::now();
        let (width, height) = img.size();
        if self.stream.is_none() {
            self.first_number = Some(number);
            let (fmt, cs) = picture_format(&img, self.opts.assume_linear);
            let assume_linear = self.opts.assume_linear;
            let (aux_formats, aux_sizes) = aux_plan(aux, assume_linear);
            let desc = InputDesc {
                width,
                height,
                format: fmt,
                colorspace: cs,
                aux: aux_formats,
                aux_sizes,
                viewport: self.opts.viewport,
            };
            let mut prepared = self.effect.prepare_with(
                self.engine,
                &desc,
                &self.plan_opts(self.opts.output_format),
            )?;
            self.note_plan(&prepared, t.elapsed());
            prepared.fps = self.opts.fps;
            let mut s = Stream::new(self.engine, prepared, fmt);
            for (n, a) in aux {
                let f = input_format(a, assume_linear).0;
                let tex = upload_image(&self.engine.ctx, &format!("aux {n}"), a, f)?;
                s.aux.insert(n.clone(), tex);
            }
            s.rate = self.opts.rate.max(1);
            s.camera = self.opts.camera;
            s.want_timings = self.opts.timings;
            self.report.frames_held_max = 2 * self.opts.queue.max(1) + s.ring_len();
            self.planes.prepare(self.engine, &s, fmt);
            self.stream = Some(s);
        }
        let s = self.stream.as_mut().expect("stream created");
        let (w, h) = (s.prepared.plan.input.width, s.prepared.plan.input.height);
        if (width, height) != (w, h) {
            // An input error, not a GPU one: the frames of a sequence have one size.
            return Err(RunError::BadInput(IoError::Decode {
                path: name.into(),
                message: format!(
                    "the frame is {}x{}, the sequence started at {w}x{h} (frame {}): the frames of a sequence must have one size",
                    width,
                    height,
                    self.first_number.unwrap_or(0)
                ),
            }));
        }
        self.planes.push(self.engine, s, img, &name)?;
        self.report.ycbcr_on_gpu = self.planes.on_gpu();
        self.numbers.push_back((number, name));
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
            let Some((out, pending)) = self.planes.next(self.engine, stream)? else {
                self.busy += t.elapsed();
                return Ok(true);
            };
            self.busy += t.elapsed();
            let rate = stream.rate as u64;
            let (input_index, sub) = (out / rate, out % rate);
            // Outputs come in input order: the front frame is this output's; it is
            // done after its last subframe (so the queue stays as short as the
            // stream's latency, whatever the sequence's length).
            let frame = if sub + 1 == rate {
                self.numbers.pop_front()
            } else {
                self.numbers.front().cloned()
            };
            let (input_number, name) = frame.unwrap_or((first + input_index, String::new()));
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

/// The formats and sizes the plan gives the auxiliary images `aux`.
type AuxPlan = (Vec<(String, Format)>, Vec<(String, (u32, u32))>);

/// [`AuxPlan`] of `aux`, each image as it will be uploaded.
fn aux_plan(aux: &[(String, Image)], assume_linear: bool) -> AuxPlan {
    let formats = aux
        .iter()
        .map(|(n, a)| (n.clone(), input_format(a, assume_linear).0))
        .collect();
    let sizes = aux
        .iter()
        .map(|(n, a)| (n.clone(), (a.width, a.height)))
        .collect();
    (formats, sizes)
}
