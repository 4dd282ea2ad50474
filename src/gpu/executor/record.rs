//! Recording a frame: one command encoder, the plan's steps in order.
//!
//! [`Prepared::record`] records into the caller's encoder (nothing is submitted);
//! [`Prepared::run`] makes an encoder, records, and submits once, all inside one
//! error scope. Per frame the executor only
//! - writes the uniform buffers whose bytes changed (the standard values `frame`,
//!   `time`, `subframe`, `jitter` and the camera; parameters are written by `set_param`),
//! - takes transient textures from the engine's pool at `Alloc { create }` and gives
//!   them back at `Free { release }`,
//! - looks bind groups up in a per-pass cache keyed by the textures bound (pooled
//!   textures by id, caller views by identity), creating one only on a miss,
//! - rotates the feedback rings after the frame.

use super::bgra::{is_bgra, TwinPipeline};
use super::compute::{encode_compute_pass, prebind_compute, ComputePath};
use super::encode::{bind_group, encode_pass, BindKey, FrameTextures};
use super::inspect::{FrameTimings, Inspection};
use super::pool::PooledTexture;
use super::stand_in::{self, StandIn};
use super::{
    CachedPipeline, CameraStd, Engine, ExecError, Execution, FrameInputs, ImageRef, PassTiming,
};
use crate::gpu::context::{GpuError, GpuTimer};
use crate::graph::plan::{Plan, Resource, Step};
use crate::shader::reflect::StdContext;
use crate::shader::{UniformLayout, UniformMember};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where a pass reads or writes an image.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Source {
    /// The caller's image `caller[i]` (input frame, aux image or output).
    Caller(usize),
    /// The texture a plan slot holds.
    Slot(usize),
    /// Ring `ring`, `back` frames ago.
    Ring { ring: usize, back: u32 },
}

/// A caller image the plan reads or writes, in the view format it needs.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct CallerRef {
    pub resource: Resource,
    pub format: Option<wgpu::TextureFormat>,
}

/// The uniform buffer of a pass and the values it was last written with.
pub(super) struct PassUniform {
    pub binding: u32,
    pub layout: UniformLayout,
    /// The shader's uniform members (types and ranges for `set_param`).
    pub members: Vec<UniformMember>,
    pub buffer: wgpu::Buffer,
    /// The static standard values (sizes); per-frame ones are set before writing.
    pub std: StdContext,
    /// Some field changes from frame to frame (`frame`, `time`, camera...).
    pub per_frame: bool,
    /// The bytes in the buffer.
    pub written: Vec<u8>,
}

/// What one prepared pass binds.
pub(super) struct GpuPass {
    pub path: String,
    /// The render pipeline (`None` for a compute-native pass).
    pub pipeline: Option<Arc<CachedPipeline>>,
    /// (binding, source, view format)
    pub textures: Vec<(u32, Source, Option<wgpu::TextureFormat>)>,
    pub samplers: Vec<(u32, wgpu::Sampler)>,
    pub uniform: Option<PassUniform>,
    pub target: Source,
    pub target_format: Option<wgpu::TextureFormat>,
    pub(super) bind_groups: Vec<(Vec<BindKey>, wgpu::BindGroup)>,
    /// A pass writing the caller's output: its pipeline for a BGRA output.
    pub(super) twin: Option<TwinPipeline>,
    /// The pass as a compute dispatch (compute execution), where it can be one.
    pub(super) compute: Option<ComputePath>,
}

impl GpuPass {
    pub fn new(
        path: String,
        pipeline: Option<Arc<CachedPipeline>>,
        textures: Vec<(u32, Source, Option<wgpu::TextureFormat>)>,
        samplers: Vec<(u32, wgpu::Sampler)>,
        uniform: Option<PassUniform>,
        target: (Source, Option<wgpu::TextureFormat>),
    ) -> Self {
        GpuPass {
            path,
            pipeline,
            textures,
            samplers,
            uniform,
            target: target.0,
            target_format: target.1,
            bind_groups: Vec::new(),
            twin: None,
            compute: None,
        }
    }
}

/// Counters of one prepared effect.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PreparedStats {
    /// Frames recorded.
    pub frames: u64,
    /// Uniform buffer writes (at prepare, for changed per-frame values, by `set_param`).
    pub uniform_writes: u64,
    /// Bind groups created (at prepare and on cache misses while recording).
    pub bind_groups_created: u64,
    /// Views made of caller textures.
    pub caller_views_created: u64,
    /// Passes recorded as compute dispatches.
    pub compute_passes: u64,
    /// Passes recorded as fragment (render) passes.
    pub fragment_passes: u64,
}

/// A plan prepared for a device; record frames with [`Prepared::record`] or
/// [`Prepared::run`].
pub struct Prepared {
    pub plan: Plan,
    pub(super) passes: Vec<GpuPass>,
    pub(super) queue: wgpu::Queue,
    /// Caller images the passes use, resolved once per frame.
    pub(super) caller: Vec<CallerRef>,
    /// The pool texture each slot holds during a frame.
    pub(super) slots: Vec<Option<usize>>,
    pub(super) rings: Vec<Vec<PooledTexture>>,
    pub(super) ring_head: Vec<usize>,
    /// Index of the frame recorded next: the standard value `frame`; `time` is
    /// `frame / fps`. Advances by one per recorded frame.
    pub frame: u64,
    /// Index of the output produced for the current input frame (see `Stream::rate`).
    pub subframe: u32,
    pub fps: f64,
    pub(super) timer: Option<GpuTimer>,
    /// Time spent creating shader modules and pipelines.
    pub pipeline_build: Duration,
    /// Views of caller textures: (texture, view format, view), oldest first.
    pub(super) views: Vec<(
        wgpu::Texture,
        Option<wgpu::TextureFormat>,
        wgpu::TextureView,
    )>,
    pub(super) stats: PreparedStats,
    /// The camera the uniforms were last written with.
    camera: Option<CameraStd>,
    /// The pass whose output is copied for tools ([`Prepared::inspect`]).
    pub(super) inspection: Option<Inspection>,
    /// Per-pass GPU times of recorded frames ([`Prepared::set_gpu_timings`]).
    pub(super) frame_timings: Option<FrameTimings>,
    /// The storage texture a compute pass writes in place of an output that
    /// cannot be stored to (stand_in.rs).
    pub(super) stand_in: Option<StandIn>,
}

const IDENTITY: [f32; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

/// The camera of an input without one.
pub(super) const NO_CAMERA: CameraStd = CameraStd {
    near: 0.1,
    far: 100.0,
    proj: IDENTITY,
    inv_proj: IDENTITY,
};

impl Prepared {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        plan: Plan,
        passes: Vec<GpuPass>,
        queue: wgpu::Queue,
        caller: Vec<CallerRef>,
        rings: Vec<Vec<PooledTexture>>,
        timer: Option<GpuTimer>,
        pipeline_build: Duration,
        stats: PreparedStats,
    ) -> Self {
        Prepared {
            ring_head: vec![0; rings.len()],
            rings,
            slots: vec![None; plan.slots.len()],
            plan,
            passes,
            queue,
            caller,
            frame: 0,
            subframe: 0,
            fps: 25.0,
            timer,
            pipeline_build,
            views: Vec::new(),
            stats,
            camera: None,
            inspection: None,
            frame_timings: None,
            stand_in: None,
        }
    }

    /// This effect's counters.
    pub fn stats(&self) -> PreparedStats {
        self.stats
    }

    /// The sub-pixel jitter this effect asks its input frames to be rendered with
    /// (an effect of the chain declares `JITTER = halton23`), or `None`. A frame
    /// source that renders its frames (the renderer) offsets frame `n` by
    /// `pattern.offset(n)` pixels and gives that offset as [`FrameInputs::jitter`].
    pub fn jitter(&self) -> Option<crate::script::JitterPattern> {
        self.plan.jitter
    }

    /// Record one frame into `encoder` (the caller's, on the engine's device), reading
    /// `inputs` and writing `output`, which must be in the plan's output format
    /// (`plan.output`) with RENDER_ATTACHMENT usage. Nothing is submitted: submit the
    /// encoder before recording the next frame of this effect (uniform values are
    /// written with `Queue::write_buffer`, which takes effect at the next submission).
    ///
    /// Errors in creating bind groups are caught in an error scope here; errors in
    /// the encoded commands surface when the caller finishes or submits the encoder.
    pub fn record<'a>(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &FrameInputs<'a>,
        output: impl Into<ImageRef<'a>>,
    ) -> Result<(), ExecError> {
        let output = output.into();
        let ctx = engine.ctx.clone();
        let mut ft = self.frame_timings.take();
        let timed = ft.as_mut().is_some_and(|f| f.begin(&ctx));
        let recorded = ctx.scoped("fxgraph frame", |_| {
            let timer = ft.as_ref().filter(|_| timed).map(|f| &f.timer);
            self.record_frame(engine, encoder, inputs, output, timer)
        });
        if let (Some(f), true, Ok(Ok(frame))) = (ft.as_mut(), timed, &recorded) {
            f.resolve(encoder, frame.clone());
        }
        self.frame_timings = ft;
        recorded??;
        Ok(())
    }

    /// Record one frame into an encoder of its own and submit it (one submission,
    /// one error scope). Returns per-pass timings (GPU times when `want_timings` and
    /// the adapter has timestamp queries; waiting for them stalls the CPU).
    pub fn run<'a>(
        &mut self,
        engine: &mut Engine,
        inputs: &FrameInputs<'a>,
        output: impl Into<ImageRef<'a>>,
        want_timings: bool,
    ) -> Result<Vec<PassTiming>, ExecError> {
        self.run_then(engine, inputs, output, want_timings, |_| Ok(()))
            .map(|(timings, ())| timings)
    }

    /// [`Prepared::run`], with `then` recording more commands after the frame's passes
    /// in the same encoder, submission and error scope (e.g. the copy of the output
    /// into a read-back buffer: [`crate::gpu::context::GpuContext::encode_readback`]).
    pub fn run_then<'a, T>(
        &mut self,
        engine: &mut Engine,
        inputs: &FrameInputs<'a>,
        output: impl Into<ImageRef<'a>>,
        want_timings: bool,
        then: impl FnOnce(&mut wgpu::CommandEncoder) -> Result<T, GpuError>,
    ) -> Result<(Vec<PassTiming>, T), ExecError> {
        let output = output.into();
        let ctx = engine.ctx.clone();
        let timer = if want_timings {
            self.timer.take()
        } else {
            None
        };
        // Without `want_timings`, the frame timings of `set_gpu_timings`, if on.
        let mut ft = if want_timings {
            None
        } else {
            self.frame_timings.take()
        };
        let timed = ft.as_mut().is_some_and(|f| f.begin(&ctx));
        let result = ctx.scoped("fxgraph frame", |device| {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("fxgraph frame"),
            });
            let frame_timer = ft.as_ref().filter(|_| timed).map(|f| &f.timer);
            let timings = self.record_frame(
                engine,
                &mut encoder,
                inputs,
                output,
                timer.as_ref().or(frame_timer),
            )?;
            if let Some(t) = &timer {
                t.resolve(&mut encoder, timings.len() as u32);
            }
            if let (Some(f), true) = (ft.as_mut(), timed) {
                f.resolve(&mut encoder, timings.clone());
            }
            let extra = then(&mut encoder)?;
            ctx.queue.submit([encoder.finish()]);
            if let (Some(f), true) = (ft.as_mut(), timed) {
                f.submitted();
            }
            Ok::<_, ExecError>((timings, extra))
        });
        if !want_timings {
            self.frame_timings = ft;
        }
        let (mut timings, extra) = match result {
            Ok(Ok(t)) => t,
            Ok(Err(e)) => {
                self.timer = self.timer.take().or(timer);
                return Err(e);
            }
            Err(e) => {
                self.timer = self.timer.take().or(timer);
                return Err(e.into());
            }
        };
        if let Some(t) = &timer {
            if let Ok(ms) = t.read_ms(&ctx, timings.len() as u32) {
                for (tm, v) in timings.iter_mut().zip(ms) {
                    tm.gpu_ms = Some(v);
                }
            }
        }
        if timer.is_some() {
            self.timer = timer;
        }
        if let Some(e) = ctx.take_uncaptured_errors().first() {
            return Err(ExecError::Gpu(GpuError::Validation {
                what: "fxgraph frame".into(),
                message: e.clone(),
            }));
        }
        Ok((timings, extra))
    }

    /// Write the uniform buffers whose bytes changed (per-frame standard values).
    fn write_uniforms(&mut self, camera: Option<CameraStd>, jitter: [f32; 2], cut: bool) {
        let cam = camera.unwrap_or(NO_CAMERA);
        let camera_changed = self.camera != Some(cam);
        self.camera = Some(cam);
        for gp in &mut self.passes {
            let Some(u) = &mut gp.uniform else { continue };
            if !u.per_frame && !camera_changed {
                continue;
            }
            u.std.frame = self.frame;
            u.std.time = self.frame as f64 / self.fps;
            u.std.fps = self.fps;
            u.std.subframe = self.subframe;
            u.std.near = cam.near;
            u.std.far = cam.far;
            u.std.proj = cam.proj;
            u.std.inv_proj = cam.inv_proj;
            u.std.jitter = jitter;
            u.std.cut = cut;
            let bytes = u.layout.write(&u.std);
            if bytes != u.written {
                self.queue.write_buffer(&u.buffer, 0, &bytes);
                u.written = bytes;
                self.stats.uniform_writes += 1;
            }
        }
    }

    /// The textures in slots go back to the engine's pool.
    fn release_slots(&mut self, engine: &mut Engine, frame_no: u64) {
        for s in &mut self.slots {
            if let Some(i) = s.take() {
                engine.pool.release(i, frame_no);
            }
        }
    }

    /// The timing of pass `pass`, recorded on `execution` since `t0` (GPU time to come).
    fn timing(&self, pass: usize, execution: Execution, t0: Instant) -> PassTiming {
        let p = &self.plan.passes[pass];
        PassTiming {
            path: p.path.clone(),
            width: p.desc.width,
            height: p.desc.height,
            format: p.desc.format.name().to_string(),
            execution,
            gpu_ms: None,
            cpu_ms: t0.elapsed().as_secs_f64() * 1e3,
            frames: 1,
        }
    }

    /// Record every step of the plan into `encoder`; returns per-pass timings
    /// (CPU recording time; GPU times are filled in by `run`).
    fn record_frame(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &FrameInputs,
        output: ImageRef,
        timer: Option<&GpuTimer>,
    ) -> Result<Vec<PassTiming>, ExecError> {
        let caller = self.resolve_caller(inputs, output)?;
        let bgra = match output {
            ImageRef::Texture(t) => is_bgra(t.format()),
            ImageRef::View(v) => is_bgra(v.texture().format()),
        };
        self.write_uniforms(inputs.camera, inputs.jitter, inputs.cut);
        engine.frames += 1;
        let frame_no = engine.frames;
        let gl = engine.is_gl();
        // Textures a failed frame left in slots go back first.
        self.release_slots(engine, frame_no);
        let mut timings = Vec::with_capacity(self.passes.len());
        let mut result = Ok(());
        for si in 0..self.plan.steps.len() {
            match self.plan.steps[si] {
                Step::Alloc { slot, create, .. } => {
                    if create || self.slots[slot].is_none() {
                        let desc = self.plan.slots[slot];
                        let i = engine
                            .pool
                            .acquire(&engine.ctx.device, gl, desc, &mut engine.ids);
                        self.slots[slot] = Some(i);
                    }
                }
                Step::Free { slot, release, .. } => {
                    if release {
                        if let Some(i) = self.slots[slot].take() {
                            engine.pool.release(i, frame_no);
                        }
                    }
                }
                Step::Run { pass } => {
                    let t0 = Instant::now();
                    let index = timings.len() as u32;
                    match self.record_pass(engine, encoder, pass, &caller, bgra, timer, index) {
                        Ok(execution) => timings.push(self.timing(pass, execution, t0)),
                        Err(e) => {
                            result = Err(e);
                            break;
                        }
                    }
                }
            }
        }
        self.release_slots(engine, frame_no);
        engine.pool.trim(frame_no);
        result?;
        // Feedback rings: this frame's output becomes "one frame ago".
        for (r, ring) in self.rings.iter().enumerate() {
            let n = ring.len();
            self.ring_head[r] = (self.ring_head[r] + n - 1) % n;
        }
        self.frame += 1;
        self.stats.frames += 1;
        Ok(timings)
    }

    /// Record pass `pass` (the `index`-th of the frame, for timestamps): as a
    /// compute dispatch where it has a compute path and its target allows storage,
    /// as a render pass otherwise; then the inspection copy. Returns the path taken.
    #[allow(clippy::too_many_arguments)]
    fn record_pass(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
        pass: usize,
        caller: &[wgpu::TextureView],
        bgra: bool,
        timer: Option<&GpuTimer>,
        index: u32,
    ) -> Result<Execution, ExecError> {
        let gp = &self.passes[pass];
        // Only a pass writing the caller's output writes a BGRA (window) texture.
        let bgra = bgra && matches!(gp.target, Source::Caller(_));
        let mut storage = gp.runs_as_compute(self.frame_textures(engine, caller));
        // An output that cannot be stored to: the dispatch writes a stand-in.
        let stand_in = match (storage || bgra, gp.output_target(engine.execution)) {
            (false, Some(target)) => {
                stand_in::for_output(&mut self.stand_in, &engine.ctx, target, caller)
            }
            _ => None,
        };
        // The inspection copy below reads the output itself (filled by the
        // stand-in's copy), in the output's format.
        let output_views = caller;
        let swapped;
        let caller = match &stand_in {
            Some(s) => {
                swapped = s.caller_views(caller);
                storage = true;
                &swapped[..]
            }
            None => caller,
        };
        let gp = &self.passes[pass];
        if gp.pipeline.is_none() && (!storage || bgra) {
            return Err(ExecError::Input(format!(
                "pass `{}` is a compute pass and its output cannot be a storage texture here (an sRGB or BGRA output, or one made without STORAGE_BINDING)",
                gp.path
            )));
        }
        let compute = !bgra && storage;
        // The render pipeline first: it may be built now (a BGRA output's twin).
        let pipeline = match compute {
            true => None,
            false => Some(self.passes[pass].pipeline_for(engine, bgra)?),
        };
        let tex = FrameTextures {
            pool: &engine.pool,
            slots: &self.slots,
            rings: &self.rings,
            ring_head: &self.ring_head,
            caller,
        };
        let gp = &mut self.passes[pass];
        let created = match pipeline {
            None => {
                self.stats.compute_passes += 1;
                let timestamps = timer.and_then(|t| t.compute_pass_writes(index));
                let created =
                    encode_compute_pass(gp, &engine.ctx.device, tex, encoder, timestamps)?;
                if let Some(s) = &stand_in {
                    s.finish(encoder);
                }
                created
            }
            Some(pipeline) => {
                self.stats.fragment_passes += 1;
                let timestamps = timer.and_then(|t| t.pass_writes(index));
                encode_pass(gp, &pipeline, &engine.ctx, tex, encoder, timestamps)?
            }
        };
        let created = created + self.make_mips(engine, encoder, pass);
        self.copy_inspected(engine, encoder, pass, output_views)?;
        engine.bind_groups_created += created;
        self.stats.bind_groups_created += created;
        Ok(if compute {
            Execution::Compute
        } else {
            Execution::Fragment
        })
    }

    /// The frame's textures as they stand (pool, slots, rings, caller views).
    fn frame_textures<'v>(
        &'v self,
        engine: &'v Engine,
        caller: &'v [wgpu::TextureView],
    ) -> FrameTextures<'v> {
        FrameTextures {
            pool: &engine.pool,
            slots: &self.slots,
            rings: &self.rings,
            ring_head: &self.ring_head,
            caller,
        }
    }

    /// Walk the plan's steps once against the pool and create the bind groups of
    /// the passes that bind no caller image: at the first frame the pool hands the
    /// same textures out again, so those passes find their bind groups made.
    pub(super) fn prebind(&mut self, engine: &mut Engine) {
        let gl = engine.is_gl();
        let frame_no = engine.frames;
        let mut slots: Vec<Option<usize>> = vec![None; self.plan.slots.len()];
        for step in &self.plan.steps {
            match *step {
                Step::Alloc { slot, create, .. } => {
                    if create || slots[slot].is_none() {
                        let desc = self.plan.slots[slot];
                        slots[slot] = Some(engine.pool.acquire(
                            &engine.ctx.device,
                            gl,
                            desc,
                            &mut engine.ids,
                        ));
                    }
                }
                Step::Free { slot, release, .. } => {
                    if release {
                        if let Some(i) = slots[slot].take() {
                            engine.pool.release(i, frame_no);
                        }
                    }
                }
                Step::Run { pass } => {
                    let gp = &mut self.passes[pass];
                    if gp
                        .textures
                        .iter()
                        .any(|(_, s, _)| matches!(s, Source::Caller(_)))
                    {
                        continue;
                    }
                    let tex = FrameTextures {
                        pool: &engine.pool,
                        slots: &slots,
                        rings: &self.rings,
                        ring_head: &self.ring_head,
                        caller: &[],
                    };
                    // A compute pass's own bind group (it has no render pipeline).
                    let created = match gp.pipeline {
                        Some(_) => bind_group(gp, &engine.ctx.device, tex).map_or(0, |(_, c)| c),
                        None => prebind_compute(gp, &engine.ctx.device, tex),
                    };
                    engine.bind_groups_created += created;
                    self.stats.bind_groups_created += created;
                }
            }
        }
        for i in slots.into_iter().flatten() {
            engine.pool.release(i, frame_no);
        }
    }
}
