//! What tools see of a frame (a viewer, a profiler), without changing it:
//!
//! - [`Prepared::inspect`]: a copy of one pass's output, made right after the pass
//!   in every recorded frame. The lifetime planner reuses an intermediate's texture
//!   once its last reader has run, so the copy is the only way to see it later; an
//!   inspected frame records one extra copy command, and the plan, its textures and
//!   every pass's output are those of an un-inspected frame.
//! - [`Prepared::set_gpu_timings`]: per-pass GPU times (timestamp queries) of frames
//!   recorded into the caller's encoder with [`Prepared::record`], read back without
//!   stalling: a frame's times are mapped once the caller has submitted it (known at
//!   the next `record`) and picked up when the mapping is done, a frame or two later.
//!   Frames recorded while a read-back is under way are not timed.

use super::record::{Prepared, Source};
use super::{Engine, ExecError, PassTiming};
use crate::gpu::context::{GpuContext, GpuTimer};
use crate::gpu::transfer::texture_2d;
use std::sync::{Arc, Mutex};

/// The pass whose output is copied, and the copy.
pub(super) struct Inspection {
    pub pass: usize,
    pub texture: Option<wgpu::Texture>,
    /// A frame has written `texture` since the pass was chosen.
    pub written: bool,
}

/// Where the read-back of the timestamps of a timed frame is.
enum TimerState {
    /// The timer may time the next frame.
    Free,
    /// Resolved into an encoder the caller submits before the next frame.
    Resolved,
    /// Mapping; `Some` once done.
    Mapping(Arc<Mutex<Option<Result<(), String>>>>),
}

/// Per-pass GPU times of recorded frames (see [`Prepared::set_gpu_timings`]).
pub(super) struct FrameTimings {
    pub timer: GpuTimer,
    state: TimerState,
    /// The CPU side of the timed frame whose GPU times are on their way.
    pending: Vec<PassTiming>,
    /// The last frame whose GPU times were read.
    last: Vec<PassTiming>,
}

impl FrameTimings {
    /// Moves the read-back on (the frame before this one was submitted: the rule of
    /// [`Prepared::record`]); true when this frame can be timed.
    pub fn begin(&mut self, ctx: &GpuContext) -> bool {
        if let TimerState::Resolved = self.state {
            self.state = TimerState::Mapping(self.timer.map_async(self.pending.len() as u32));
            return false;
        }
        if let TimerState::Mapping(done) = &self.state {
            let _ = ctx.device.poll(wgpu::PollType::Poll);
            let result = done.lock().unwrap_or_else(|e| e.into_inner()).clone();
            match result {
                None => return false,
                Some(Ok(())) => match self.timer.mapped_ms(ctx, self.pending.len() as u32) {
                    Ok(ms) => {
                        let mut frame = std::mem::take(&mut self.pending);
                        for (t, v) in frame.iter_mut().zip(ms) {
                            t.gpu_ms = Some(v);
                        }
                        self.last = frame;
                    }
                    Err(e) => log::warn!("GPU pass times: {e}"),
                },
                Some(Err(e)) => log::warn!("GPU pass times: {e}"),
            }
            self.state = TimerState::Free;
        }
        true
    }

    /// The frame's passes were recorded with timestamp writes into `encoder`.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder, frame: Vec<PassTiming>) {
        self.timer.resolve(encoder, frame.len() as u32);
        self.pending = frame;
        self.state = TimerState::Resolved;
    }

    /// The encoder of [`FrameTimings::resolve`] was submitted: start the read-back.
    pub fn submitted(&mut self) {
        if let TimerState::Resolved = self.state {
            self.state = TimerState::Mapping(self.timer.map_async(self.pending.len() as u32));
        }
    }
}

impl Prepared {
    /// Copy the output of pass `pass` (an index into `plan.passes`) after the pass
    /// runs in every following frame ([`Prepared::inspected`]); `None` stops. The plan
    /// is not changed (see the module's documentation). A pass that writes the
    /// caller's output is copied from the output texture, which then needs
    /// `COPY_SRC` usage.
    pub fn inspect(&mut self, pass: Option<usize>) -> Result<(), ExecError> {
        let Some(pass) = pass else {
            self.inspection = None;
            return Ok(());
        };
        if pass >= self.plan.passes.len() {
            return Err(ExecError::Input(format!(
                "no pass {pass} to inspect: the plan has {}",
                self.plan.passes.len()
            )));
        }
        if self.inspection.as_ref().is_some_and(|i| i.pass == pass) {
            return Ok(());
        }
        self.inspection = Some(Inspection {
            pass,
            texture: None,
            written: false,
        });
        Ok(())
    }

    /// The pass being inspected, if any.
    pub fn inspected_pass(&self) -> Option<usize> {
        self.inspection.as_ref().map(|i| i.pass)
    }

    /// The copy of the inspected pass's output from the last frame recorded (its
    /// size and format are the pass's: `plan.passes[pass].desc`; usages
    /// `TEXTURE_BINDING | COPY_SRC`, and an 8-bit texture can be viewed as sRGB or
    /// raw); `None` before the first frame recorded since [`Prepared::inspect`].
    /// Like the output, it holds the frame once the caller's encoder is submitted.
    pub fn inspected(&self) -> Option<&wgpu::Texture> {
        self.inspection
            .as_ref()
            .filter(|i| i.written)
            .and_then(|i| i.texture.as_ref())
    }

    /// Time every pass of the frames recorded from now on (`on`), on the GPU with
    /// timestamp queries, read back without stalling ([`Prepared::gpu_timings`]).
    /// Returns false when the adapter has no timestamp queries (nothing is timed).
    pub fn set_gpu_timings(&mut self, engine: &Engine, on: bool) -> bool {
        if !on {
            self.frame_timings = None;
            return engine.ctx.timestamps;
        }
        if self.frame_timings.is_none() {
            self.frame_timings =
                GpuTimer::new(&engine.ctx, self.plan.passes.len() as u32).map(|timer| {
                    FrameTimings {
                        timer,
                        state: TimerState::Free,
                        pending: Vec::new(),
                        last: Vec::new(),
                    }
                });
        }
        self.frame_timings.is_some()
    }

    /// Per-pass times of the last timed frame whose timestamps have been read (GPU
    /// times in `gpu_ms`, the CPU time to record each pass in `cpu_ms`); empty until
    /// one has been (see [`Prepared::set_gpu_timings`]).
    pub fn gpu_timings(&self) -> &[PassTiming] {
        self.frame_timings
            .as_ref()
            .map(|f| f.last.as_slice())
            .unwrap_or(&[])
    }

    /// Record the copy of pass `pass`'s output when it is the inspected one.
    pub(super) fn copy_inspected(
        &mut self,
        engine: &Engine,
        encoder: &mut wgpu::CommandEncoder,
        pass: usize,
        caller: &[wgpu::TextureView],
    ) -> Result<(), ExecError> {
        let Some(insp) = self.inspection.as_mut().filter(|i| i.pass == pass) else {
            return Ok(());
        };
        let gp = &self.passes[pass];
        let src = match &gp.target {
            Source::Caller(i) => caller[*i].texture().clone(),
            Source::Slot(s) => engine
                .pool
                .get(self.slots[*s].expect("allocated before use"))
                .texture
                .clone(),
            Source::Ring { ring, back } => {
                let r = &self.rings[*ring];
                r[(self.ring_head[*ring] + *back as usize) % r.len()]
                    .texture
                    .clone()
            }
        };
        if !src.usage().contains(wgpu::TextureUsages::COPY_SRC) {
            return Err(ExecError::Input(format!(
                "pass `{}` writes a texture without COPY_SRC usage, which cannot be inspected",
                gp.path
            )));
        }
        let fits = insp
            .texture
            .as_ref()
            .is_some_and(|t| t.size() == src.size() && t.format() == src.format());
        if !fits {
            let format = src.format();
            let alternate = match format {
                wgpu::TextureFormat::Rgba8Unorm => vec![wgpu::TextureFormat::Rgba8UnormSrgb],
                wgpu::TextureFormat::Rgba8UnormSrgb => vec![wgpu::TextureFormat::Rgba8Unorm],
                _ => Vec::new(),
            };
            let alternate = if engine.is_gl() {
                Vec::new()
            } else {
                alternate
            };
            let usage = wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC;
            insp.texture = Some(engine.ctx.device.create_texture(&texture_2d(
                &format!("fxgraph inspected {}", gp.path),
                (src.width(), src.height()),
                format,
                usage,
                &alternate,
            )));
        }
        let dst = insp.texture.as_ref().expect("made above");
        encoder.copy_texture_to_texture(src.as_image_copy(), dst.as_image_copy(), src.size());
        insp.written = true;
        Ok(())
    }
}
