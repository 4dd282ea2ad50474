//! Rendered sequences: `fxrun EFFECT... --scene SCENE --frames A..B --fps N` and
//! `--time SECONDS`. Frame n is the scene at time n / fps, rendered with the
//! motion of the previous frame time (n − 1) / fps (`AUX.motion`) and, when the
//! chain asks for it, the frame's sub-pixel jitter; the frames go through the
//! effect's [`Stream`] exactly like a file sequence (`IN[-1]`, `PASS.x[-1]`,
//! `IN[+1]`: the renderer renders ahead as far as the chain's latency needs) and
//! out to a [`FrameSink`] on the encode thread.
//!
//! Everything about frame n depends on n alone (its time, its previous time, its
//! jitter index), never on what was rendered before it, so frame n of a sequence
//! equals frame n rendered alone with the same history before it: `--frames`
//! slices on several machines give byte-identical results (docs/distributed.md).

use super::effect::Effect;
use super::error::RunError;
use super::frames::FrameSink;
use super::pipeline::{spawn_encoder, EncodeResult};
use super::report::{ms, JobKind, MemoryReport, Progress, RunReport, SceneStats};
use super::scene::{prepare, SceneJob};
use super::stage_messages::Encoded;
use crate::gpu::executor::Engine;
use crate::gpu::stream::{FrameExtras, Stream};
use crate::graph::plan::{PlanOptions, ReusePolicy};
use crate::render::renderer::RenderStats;
use crate::render::{FrameMotion, RenderOutput, Renderer};
use crate::scene::{CameraPath, Playback, Scene};
use crate::script::types::Format;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The times of a rendered sequence.
#[derive(Debug, Clone)]
pub struct SceneTimes {
    /// Frames per second: frame n is at n / fps seconds.
    pub fps: f64,
    /// The output frames, first and last (inclusive).
    pub frames: (u64, u64),
    /// Frames rendered before `frames.0` without being written, on top of the
    /// chain's own history, so that feedback settles (`--warmup`).
    pub warmup: u64,
    /// `--time`: `frames` is the one frame n0 = round(time · fps), rendered at
    /// exactly this time; the history frames before it are at time − k / fps.
    /// When time is n0 / fps the frames are those of a sequence (bit for bit).
    pub time: Option<f64>,
}

impl SceneTimes {
    /// One frame at `time` seconds (≥ 0).
    pub fn at(time: f64, fps: f64, warmup: u64) -> SceneTimes {
        let n0 = (time * fps).round().max(0.0) as u64;
        SceneTimes {
            fps,
            frames: (n0, n0),
            warmup,
            time: Some(time),
        }
    }

    /// The time of frame `n` (its number is also its index in the jitter
    /// sequence).
    fn time_of(&self, n: u64) -> f64 {
        let on_grid = n as f64 / self.fps;
        match self.time {
            Some(t) if (t * self.fps - self.frames.0 as f64).abs() > 1e-9 => {
                t + (n as f64 - self.frames.0 as f64) / self.fps
            }
            _ => on_grid,
        }
    }
}

/// Which animations play for `job` (all by default).
pub(super) fn playback(job: &SceneJob, scene: &Scene) -> Result<Playback, RunError> {
    match &job.animation {
        Some(spec) => Playback::parse(spec, scene, job.looping)
            .map_err(|e| super::scene::scene_error(&job.scene, e)),
        None => Ok(Playback {
            looping: job.looping,
            ..Playback::default()
        }),
    }
}

/// The instances' world transforms (scene order) of a pose.
/// One texture copied (the renderer draws the next frame into its own).
fn copy_of(engine: &Engine, enc: &mut wgpu::CommandEncoder, tex: &wgpu::Texture) -> wgpu::Texture {
    let copy = engine.ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("rendered frame (held by the stream)"),
        size: tex.size(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: tex.format(),
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    enc.copy_texture_to_texture(tex.as_image_copy(), copy.as_image_copy(), tex.size());
    copy
}

/// Renders the frames of `times`, runs the job's effects over them as a sequence
/// and writes the outputs to `sink` (`output_format`: the format its files take).
/// `stop` ends the run after the frame in flight (Ctrl-C).
#[allow(clippy::too_many_arguments)]
pub fn run_scene_sequence(
    job: &SceneJob,
    times: &SceneTimes,
    engine: &mut Engine,
    sink: Box<dyn FrameSink>,
    output_format: Format,
    stop: Arc<AtomicBool>,
    mut progress: impl FnMut(Progress),
) -> Result<RunReport, RunError> {
    let t_all = Instant::now();
    if !(times.fps.is_finite() && times.fps > 0.0) {
        return Err(RunError::Other(format!("fps {} is not above 0", times.fps)));
    }
    let mut stats = job.initial_stats();
    let (scene, renderer, effect) = prepare(job, engine, &mut stats)?;
    let path = CameraPath::parse(job.camera.as_deref(), &scene)
        .map_err(|e| super::scene::scene_error(&job.scene, e))?;
    let playback = playback(job, &scene)?;
    let mut report = RunReport {
        job: JobKind::Scene,
        adapter: engine.ctx.info.name.clone(),
        backend: format!("{:?}", engine.ctx.info.backend),
        ..Default::default()
    };
    let (stream, (from, to)) = effect_stream(
        (job, times),
        engine,
        effect,
        &renderer,
        output_format,
        &mut report,
    )?;
    let (enc_tx, enc_rx) = sync_channel::<Encoded>(2);
    let halt = Arc::new(AtomicBool::new(false));
    let complete = Arc::new(AtomicBool::new(false));
    let encoder = spawn_encoder(sink, enc_rx, false, halt.clone(), complete.clone())?;
    let mut run = SceneRun {
        job,
        times,
        scene: &scene,
        path: &path,
        playback: &playback,
        animated: scene.is_animated(),
        renderer,
        stream,
        timer: job
            .timings
            .then(|| crate::gpu::context::GpuTimer::new(&engine.ctx, 64))
            .flatten(),
        stats,
        report,
        output_format,
        enc_tx,
        emitted: from,
        gpu_busy: Duration::ZERO,
    };
    let fatal = run.frames(engine, (from, to), (&halt, &stop), t_all, &mut progress);
    // a y4m or video output is made final only when every frame went through
    complete.store(
        fatal.is_none() && !run.report.interrupted && !halt.load(Ordering::Relaxed),
        Ordering::SeqCst,
    );
    end_run(run, encoder, fatal, t_all)
}

/// A rendered sequence while its frames go through: what each frame is rendered
/// from, the effect's stream, the queue to the encoder and the statistics gathered.
struct SceneRun<'a> {
    job: &'a SceneJob,
    times: &'a SceneTimes,
    scene: &'a Scene,
    path: &'a CameraPath,
    playback: &'a Playback,
    /// Lights on animated nodes move with them.
    animated: bool,
    renderer: Renderer,
    /// The effect (none: the rendered HDR image itself is written).
    stream: Option<Stream>,
    timer: Option<crate::gpu::context::GpuTimer>,
    stats: SceneStats,
    report: RunReport,
    output_format: Format,
    enc_tx: SyncSender<Encoded>,
    /// The number of the next frame the stream hands back.
    emitted: u64,
    gpu_busy: Duration,
}

impl SceneRun<'_> {
    /// Renders frames `from..=to` through the stream until `halt` (a failed write) or
    /// `stop` (Ctrl-C: the run is marked interrupted) ends them early, reporting
    /// progress after each; the error that ended the run.
    fn frames(
        &mut self,
        engine: &mut Engine,
        (from, to): (u64, u64),
        (halt, stop): (&AtomicBool, &AtomicBool),
        t_all: Instant,
        progress: &mut impl FnMut(Progress),
    ) -> Option<RunError> {
        let (first, last) = self.times.frames;
        for n in from..=to {
            if halt.load(Ordering::Relaxed) {
                break;
            }
            match self.frame(engine, n, n == to) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => return Some(e),
            }
            progress(Progress {
                done: n.saturating_sub(first).min(last - first + 1),
                total: Some(last - first + 1),
                elapsed: t_all.elapsed(),
            });
            if stop.load(Ordering::Relaxed) {
                self.report.interrupted = true;
                break;
            }
        }
        None
    }

    /// Renders frame `n`, adds its statistics and sends the outputs that are ready to
    /// the encoder; `Ok(false)` when the encoder is gone.
    fn frame(&mut self, engine: &mut Engine, n: u64, is_last: bool) -> Result<bool, RunError> {
        let t0 = Instant::now();
        let (first, last) = self.times.frames;
        let t = self.times.time_of(n);
        // the frame's sub-pixel offset when the chain declares JITTER (its index
        // is the frame number, so a frame's jitter depends on n alone)
        let jitter = self
            .stream
            .as_ref()
            .and_then(|s| s.prepared.jitter())
            .map_or([0.0, 0.0], |p| p.offset(n));
        let (out, rs, cut) = self.render(engine, t, jitter)?;
        self.report.frames_in += 1;
        // `--time` with `--gbuffer`: the one output frame's G-buffer, its motion
        // vectors those of the previous frame time
        if let (Some(dir), true) = (&self.job.gbuffer, n == first && first == last) {
            super::gbuffer::write_gbuffer(dir, &out, &engine.ctx, &self.job.scene)?;
        }
        add_render_stats(&mut self.stats, &rs);
        let sent = match self.stream.as_mut() {
            Some(s) => push_and_drain(
                engine,
                s,
                &out,
                (jitter, cut),
                is_last,
                (first, last),
                &mut self.emitted,
                &self.enc_tx,
                self.output_format,
            ),
            None => self.send_rendered_image(engine, &out, n, t),
        };
        self.gpu_busy += t0.elapsed();
        sent
    }

    /// Renders the scene at time `t` (its motion from `t` − 1 / fps), offset by
    /// `jitter`; with whether the camera jumped there (a cut).
    fn render(
        &mut self,
        engine: &Engine,
        t: f64,
        jitter: [f32; 2],
    ) -> Result<(RenderOutput, RenderStats, bool), RunError> {
        let (scene, path, playback) = (self.scene, self.path, self.playback);
        let dt = 1.0 / self.times.fps;
        let (pose, prev) = (scene.pose(t, playback), scene.pose(t - dt, playback));
        if self.animated {
            // lights on animated nodes move with them
            self.renderer.set_lights(pose.lights.clone());
        }
        // a camera that jumps (a STEP key) starts a new shot: no camera motion,
        // and effects see the standard value `cut`
        let cut = path.cuts(scene, playback, t - dt, t);
        let motion = FrameMotion {
            prev_camera: Some(path.at(scene, Some(&prev), t - dt)),
            jitter,
            cut,
            ..FrameMotion::posed(scene, &pose, &prev)
        };
        let camera = path.at(scene, Some(&pose), t);
        let (out, rs) = self
            .renderer
            .render_frame(
                &engine.ctx,
                &camera,
                &motion,
                self.job.width,
                self.job.height,
                self.job.technique,
                self.timer.as_ref(),
            )
            .map_err(|e| super::scene::render_error(&self.job.scene, e))?;
        Ok((out, rs, cut))
    }

    /// No effect: the rendered HDR image itself goes to the encoder (frames inside
    /// the output range); `Ok(false)` when the encoder is gone.
    fn send_rendered_image(
        &self,
        engine: &Engine,
        out: &RenderOutput,
        n: u64,
        t: f64,
    ) -> Result<bool, RunError> {
        let (first, last) = self.times.frames;
        let ctx = engine.ctx.clone();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let pending = ctx.encode_readback(&mut enc, &out.scene);
        ctx.queue.submit([enc.finish()]);
        pending
            .map_err(RunError::from)
            .map(|pending| {
                (first..=last).contains(&n)
                    && self
                        .enc_tx
                        .send(Encoded {
                            index: (n - first) as usize,
                            number: n,
                            name: format!("{} at {:.4} s", self.job.scene, t),
                            pending: super::stage_messages::Readback::Texture(pending),
                            format: Format::Rgba16f,
                            gpu: None,
                            decode: None,
                        })
                        .is_err()
            })
            .map(|closed| !closed)
    }
}

/// Closes the queue to the encoder and waits for it; then the error that ended the run
/// (or the first failed write), else its report: the effect's pass timings, the
/// renderer's statistics and what the encoder wrote.
fn end_run(
    run: SceneRun,
    encoder: std::thread::JoinHandle<EncodeResult>,
    fatal: Option<RunError>,
    t_all: Instant,
) -> Result<RunReport, RunError> {
    // (the encoder ends after the last frame once the queue closes)
    let SceneRun {
        mut report,
        stream,
        stats,
        gpu_busy,
        enc_tx,
        ..
    } = run;
    drop(enc_tx);
    let mut enc = encoder
        .join()
        .map_err(|_| RunError::Other("the encode thread panicked".into()))?;
    if let Some(e) = fatal {
        return Err(e);
    }
    if let Some(f) = enc.failed.drain(..).next() {
        return Err(f.error);
    }
    if let Some(s) = &stream {
        report.passes = s.median_timings();
    }
    report.done = enc.done;
    report.stages.gpu_busy_ms = ms(gpu_busy);
    report.stages.encode_busy_ms = ms(enc.busy);
    report.stages.readback_wait_ms = ms(enc.wait);
    report.steps.readback_ms = ms(enc.last_wait);
    report.scene = Some(stats);
    report.wall_ms = ms(t_all.elapsed());
    Ok(report)
}

/// Adds one rendered frame's statistics to the sequence's: times summed, the
/// counts of the last frame.
fn add_render_stats(stats: &mut SceneStats, rs: &RenderStats) {
    stats.render_cpu_ms += rs.cpu_ms;
    stats.render_pipelines_ms += rs.pipeline_ms;
    for (name, ms) in &rs.cpu_split {
        match stats.render_cpu_split.iter_mut().find(|(n, _)| n == name) {
            Some(p) => p.1 += ms,
            None => stats.render_cpu_split.push((name.clone(), *ms)),
        }
    }
    stats.render_gpu_ms = match (stats.render_gpu_ms, rs.gpu_ms) {
        (Some(a), Some(b)) => Some(a + b),
        (_, b) => b,
    };
    stats.shadow_layers_rendered += rs.shadow_layers_rendered;
    stats.take_frame_counts(rs);
}

/// The job's effect prepared as a stream over the rendered frames (none without an
/// effect), and the frames to render: the history and warm-up before the first
/// output, the latency after the last. The plan's figures go to `report`.
fn effect_stream(
    (job, times): (&SceneJob, &SceneTimes),
    engine: &mut Engine,
    effect: Option<Effect>,
    renderer: &Renderer,
    output_format: Format,
    report: &mut RunReport,
) -> Result<(Option<Stream>, (u64, u64)), RunError> {
    let (first, last) = times.frames;
    let (mut stream, history, latency) = match effect {
        Some(mut effect) => {
            let (s, h, l) = stream_for(job, times, engine, &mut effect, renderer, output_format)?;
            report.plans = 1;
            report.memory = MemoryReport::of(&s.prepared.plan);
            (Some(s), h, l)
        }
        None => (None, 0, 0),
    };
    // Frames rendered: the history and warm-up before the first output, the
    // latency after the last.
    let from = first.saturating_sub(history + times.warmup);
    let to = last.saturating_add(latency);
    if let Some(s) = stream.as_mut() {
        s.frame_offset = from;
    }
    report.frames_total = Some(last - first + 1);
    report.frames_held_max = 2 + stream.as_ref().map_or(1, |s| s.ring_len());
    Ok((stream, (from, to)))
}

/// The effect prepared for the rendered frames, as a stream; with its history
/// and latency in frames.
fn stream_for(
    job: &SceneJob,
    times: &SceneTimes,
    engine: &mut Engine,
    effect: &mut Effect,
    renderer: &Renderer,
    output_format: Format,
) -> Result<(Stream, u64, u64), RunError> {
    let job_aux = super::scene::upload_job_aux(job, &engine.ctx)?;
    let desc = job.effect_input(renderer, &job_aux);
    let mut prepared = effect.prepare_with(
        engine,
        &desc,
        &PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(output_format),
        },
    )?;
    prepared.fps = times.fps;
    let (history, latency) = (prepared.plan.history as u64, prepared.plan.latency as u64);
    let mut s = Stream::new(engine, prepared, Format::Rgba16f);
    s.aux = job_aux.into_iter().map(|(n, t, ..)| (n, t)).collect();
    s.want_timings = job.timings;
    Ok((s, history, latency))
}

/// Pushes a rendered frame into the stream (copies of its textures when the
/// stream holds more than one frame) and sends every output that is ready and
/// inside `(first, last)` to the encoder; `Ok(false)` when the encoder is gone.
#[allow(clippy::too_many_arguments)]
fn push_and_drain(
    engine: &mut Engine,
    stream: &mut Stream,
    out: &crate::render::RenderOutput,
    (jitter, cut): ([f32; 2], bool),
    is_last: bool,
    (first, last): (u64, u64),
    emitted: &mut u64,
    enc_tx: &std::sync::mpsc::SyncSender<Encoded>,
    output_format: Format,
) -> Result<bool, RunError> {
    let (input, aux) = if stream.ring_len() > 1 {
        let ctx = engine.ctx.clone();
        let mut enc = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("rendered frame copies"),
            });
        let input = copy_of(engine, &mut enc, &out.scene);
        let aux: HashMap<String, wgpu::Texture> = out
            .aux
            .iter()
            .map(|(n, t)| (n.clone(), copy_of(engine, &mut enc, t)))
            .collect();
        ctx.queue.submit([enc.finish()]);
        (input, aux)
    } else {
        (
            out.scene.clone(),
            out.aux
                .iter()
                .map(|(n, t)| (n.clone(), t.clone()))
                .collect(),
        )
    };
    stream.push_frame(
        input,
        FrameExtras {
            aux,
            camera: Some(out.camera),
            jitter,
            cut,
        },
    );
    if is_last {
        stream.end();
    }
    while let Some((_, pending)) = stream.next_read_back(engine)? {
        let n = *emitted;
        *emitted += 1;
        if n < first || n > last {
            continue;
        }
        let e = Encoded {
            index: (n - first) as usize,
            number: n,
            name: format!("frame {n}"),
            pending: super::stage_messages::Readback::Texture(pending),
            format: output_format,
            gpu: None,
            decode: None,
        };
        if enc_tx.send(e).is_err() {
            return Ok(false);
        }
    }
    Ok(true)
}
