//! Streaming frames through a prepared effect: `push` frames, run the outputs that
//! are ready with `next`, and `end` the input so the last ones become ready.
//!
//! Semantics (docs/language.md, "Temporal references"):
//! - `IN[-n]` / `IN[+n]` read the input `n` frames earlier / later; at the first
//!   and last frames they clamp to the nearest frame that exists.
//! - With later-frame references (latency `L`), output `t` is ready when input
//!   `t + L` is pushed, or after `end` for the last `L` frames. There is exactly
//!   one output per input (`rate` outputs with `rate > 1`), in order.
//! - `PASS.x[-n]` (feedback) reads the persistent ring of the pass, zero before the
//!   first frame.
//! - A frame pushed with [`FrameExtras`] (its own auxiliary images, camera and
//!   sub-pixel jitter) gives them to its output `t`.
//!
//! Each input frame is uploaded once into a texture that stays in a ring of
//! `history + latency + 1` textures (recycled, never re-uploaded), and transient
//! textures come from the engine's pool, so a stream allocates nothing per frame
//! after the first. Each output is one frame recorded by [`Prepared::run`]: one
//! command encoder, one submission.

use super::context::{GpuError, PendingReadback};
use super::executor::{
    wgpu_format, CameraStd, Engine, ExecError, FrameInputs, PassTiming, Prepared,
};
use super::transfer::{create_output, image_bytes};
use super::yuv::PlanesToRgb;
use crate::graph::plan::Resource;
use crate::pixels::Image;
use crate::script::types::Format;
use std::collections::{HashMap, VecDeque};

/// What a frame made on the device (a rendered scene) brings besides its image:
/// its own auxiliary images and camera, which the effect reads with that frame's
/// output (the stream's [`Stream::aux`] and [`Stream::camera`] are for frames
/// without them), and the sub-pixel jitter it was rendered with.
#[derive(Debug, Clone, Default)]
pub struct FrameExtras {
    pub aux: HashMap<String, wgpu::Texture>,
    pub camera: Option<CameraStd>,
    /// The offset the frame was rendered with, in pixels from the pixel centre, x
    /// right, y down: the standard value `jitter` ([`FrameInputs::jitter`]). A
    /// renderer sets it to `pattern.offset(n)` for frame `n` when
    /// [`Prepared::jitter`] asks for a pattern; `[0, 0]` otherwise.
    pub jitter: [f32; 2],
    /// The camera cut between the previous frame and this one: the standard
    /// value `cut` ([`FrameInputs::cut`]).
    pub cut: bool,
}

/// An input frame held in the ring.
struct Held {
    index: u64,
    input: wgpu::Texture,
    /// Set for frames pushed with [`Stream::push_frame`] or [`Stream::push_image_with`].
    extras: Option<FrameExtras>,
    /// The input texture is the stream's own (an uploaded image): reused for a
    /// later upload once the frame leaves the ring.
    recycle: bool,
}

/// A prepared effect run over a sequence of frames.
pub struct Stream {
    pub prepared: Prepared,
    offsets: Vec<i32>,
    history: u32,
    latency: u32,
    frames: VecDeque<Held>,
    spare: Vec<wgpu::Texture>,
    pushed: u64,
    emitted: u64,
    ended: bool,
    subframe: u32,
    /// Outputs per input frame (2 for field-rate deinterlacing); shaders see the
    /// index as the standard value `subframe`. Default 1.
    pub rate: u32,
    output: wgpu::Texture,
    input_format: Format,
    /// Auxiliary images, the same for every frame.
    pub aux: HashMap<String, wgpu::Texture>,
    pub camera: Option<CameraStd>,
    /// Number of the first pushed frame: the standard values `frame` and `time`
    /// (= frame / fps) of output t are those of frame `frame_offset + t` (a
    /// rendered sequence starts at its first frame's scene time). Default 0.
    pub frame_offset: u64,
    /// Collect per-pass timings of every frame.
    pub want_timings: bool,
    /// Timings of the last frame run (when `want_timings`).
    pub last_timings: Vec<PassTiming>,
    /// Per pass, the GPU and CPU milliseconds of every timed frame.
    samples: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Stream {
    /// `input_format` is the format pushed images are uploaded as.
    pub fn new(engine: &Engine, prepared: Prepared, input_format: Format) -> Self {
        let mut offsets: Vec<i32> = prepared
            .plan
            .passes
            .iter()
            .flat_map(|p| p.inputs.iter())
            .filter_map(|i| match i.resource {
                Resource::Input { frame } => Some(frame),
                _ => None,
            })
            .collect();
        offsets.sort();
        offsets.dedup();
        let out = prepared.plan.output;
        let output = create_output(&engine.ctx, out.width, out.height, out.format);
        Stream {
            history: prepared.plan.history,
            latency: prepared.plan.latency,
            offsets,
            frames: VecDeque::new(),
            spare: Vec::new(),
            pushed: 0,
            emitted: 0,
            ended: false,
            subframe: 0,
            rate: 1,
            output,
            input_format,
            prepared,
            aux: HashMap::new(),
            camera: None,
            frame_offset: 0,
            want_timings: false,
            last_timings: Vec::new(),
            samples: Vec::new(),
        }
    }

    /// Per-pass timings over every timed frame: the last frame's passes with the
    /// median GPU and CPU times of all frames (`frames` says how many).
    pub fn median_timings(&self) -> Vec<PassTiming> {
        let median = |v: &[f64]| {
            let mut v = v.to_vec();
            v.sort_by(f64::total_cmp);
            (!v.is_empty()).then(|| v[v.len() / 2])
        };
        self.last_timings
            .iter()
            .zip(&self.samples)
            .map(|(t, (gpu, cpu))| PassTiming {
                gpu_ms: median(gpu),
                cpu_ms: median(cpu).unwrap_or(t.cpu_ms),
                frames: cpu.len() as u32,
                ..t.clone()
            })
            .collect()
    }

    /// Frames of delay between an input and its output.
    pub fn latency(&self) -> u32 {
        self.latency
    }

    /// Input frames kept (the memory bound of the input ring).
    pub fn ring_len(&self) -> usize {
        (self.history + self.latency + 1) as usize
    }

    /// The output texture, holding the last output produced.
    pub fn output(&self) -> &wgpu::Texture {
        &self.output
    }

    /// Frames pushed so far.
    pub fn pushed(&self) -> u64 {
        self.pushed
    }

    /// Upload an image (into a recycled texture) and queue it.
    pub fn push_image(&mut self, engine: &Engine, img: &Image) -> Result<(), GpuError> {
        let input = self.input_texture(engine, img)?;
        self.push_texture(input);
        Ok(())
    }

    /// [`Stream::push_image`] with the frame's own auxiliary images, camera and
    /// jitter (as [`Stream::push_frame`] for a frame made on the device).
    pub fn push_image_with(
        &mut self,
        engine: &Engine,
        img: &Image,
        extras: FrameExtras,
    ) -> Result<(), GpuError> {
        let input = self.input_texture(engine, img)?;
        self.hold(input, Some(extras), true);
        Ok(())
    }

    /// Queue `input` as the next frame; `recycle`: its texture may take a later
    /// uploaded frame once the ring lets it go.
    fn hold(&mut self, input: wgpu::Texture, extras: Option<FrameExtras>, recycle: bool) {
        self.frames.push_back(Held {
            index: self.pushed,
            input,
            extras,
            recycle,
        });
        self.pushed += 1;
    }

    fn input_texture(&mut self, engine: &Engine, img: &Image) -> Result<wgpu::Texture, GpuError> {
        let ctx = &engine.ctx;
        let (w, h) = (
            self.prepared.plan.input.width,
            self.prepared.plan.input.height,
        );
        if (img.width, img.height) != (w, h) {
            return Err(GpuError::Validation {
                what: "sequence frame".into(),
                message: format!(
                    "frame is {}x{}, the sequence started at {w}x{h}",
                    img.width, img.height
                ),
            });
        }
        let bytes = image_bytes(img, self.input_format);
        match self.spare.pop() {
            Some(tex) => {
                let texel = (bytes.len() / (w as usize * h as usize)) as u32;
                ctx.queue.write_texture(
                    tex.as_image_copy(),
                    &bytes,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(w * texel),
                        rows_per_image: None,
                    },
                    tex.size(),
                );
                Ok(tex)
            }
            None => ctx.upload_texture(
                &format!("sequence input {}", self.pushed),
                w,
                h,
                wgpu_format(self.input_format),
                &bytes,
                wgpu::TextureUsages::empty(),
            ),
        }
    }

    /// Convert a Y'CbCr frame's planes on the device into a recycled input texture
    /// (see [`PlanesToRgb::convert`]) and queue it; `conversion` makes textures of
    /// the stream's input format.
    pub fn push_planes(
        &mut self,
        engine: &Engine,
        conversion: &mut PlanesToRgb,
        planes: [&[u8]; 3],
        fields: bool,
    ) -> Result<(), GpuError> {
        let input = match self.spare.pop() {
            Some(t) => t,
            None => conversion
                .create_texture(&engine.ctx, &format!("sequence input {}", self.pushed))?,
        };
        conversion.convert(&engine.ctx, planes, fields, &input)?;
        self.push_texture(input);
        Ok(())
    }

    /// Queue the next input frame (uploaded once). Outputs become ready as the
    /// graph's latency allows: run them with [`Stream::next`].
    pub fn push_texture(&mut self, input: wgpu::Texture) {
        self.hold(input, None, true);
    }

    /// Queue a frame made on the device with its own auxiliary images and camera
    /// (a rendered scene). The textures must stay unchanged while the ring holds
    /// the frame ([`Stream::ring_len`] frames): a producer that draws every frame
    /// into the same textures passes copies unless the ring holds one frame.
    pub fn push_frame(&mut self, input: wgpu::Texture, extras: FrameExtras) {
        self.hold(input, Some(extras), false);
    }

    /// Mark the end of the input: the last `latency` outputs become ready.
    pub fn end(&mut self) {
        self.ended = true;
    }

    /// Run the next ready output into [`Stream::output`]; returns its index
    /// (`input frame * rate + subframe`), or `None` when no output is ready (push
    /// more frames, or call [`Stream::end`]).
    pub fn next(&mut self, engine: &mut Engine) -> Result<Option<u64>, ExecError> {
        Ok(self.next_then(engine, |_, _| Ok(()))?.map(|(i, ())| i))
    }

    /// [`Stream::next`], copying the output into a read-back buffer in the same
    /// submission as the frame's passes (one encoder, one submission per output).
    pub fn next_read_back(
        &mut self,
        engine: &mut Engine,
    ) -> Result<Option<(u64, PendingReadback)>, ExecError> {
        let ctx = engine.ctx.clone();
        self.next_then(engine, |enc, output| ctx.encode_readback(enc, output))
    }

    /// [`Stream::next`], then `then(encoder, output)` in the same command encoder
    /// as the frame's passes (a copy of the output, a conversion of it).
    pub fn next_then<T>(
        &mut self,
        engine: &mut Engine,
        then: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::Texture) -> Result<T, GpuError>,
    ) -> Result<Option<(u64, T)>, ExecError> {
        let t = self.emitted;
        let ready = if self.ended {
            t < self.pushed
        } else {
            self.pushed > t + self.latency as u64
        };
        if !ready {
            return Ok(None);
        }
        let s = self.subframe;
        self.prepared.frame = self.frame_offset + t;
        self.prepared.subframe = s;
        let extra = self.produce(engine, then)?;
        self.subframe += 1;
        if self.subframe == self.rate {
            self.subframe = 0;
            self.emitted += 1;
            // Output t+1 needs frames from t+1-history on.
            let keep_from = (t + 1).saturating_sub(self.history as u64);
            while self.frames.front().is_some_and(|f| f.index < keep_from) {
                let f = self.frames.pop_front().expect("front exists");
                if f.recycle {
                    self.spare.push(f.input);
                }
            }
        }
        Ok(Some((t * self.rate as u64 + s as u64, extra)))
    }

    fn produce<T>(
        &mut self,
        engine: &mut Engine,
        then: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::Texture) -> Result<T, GpuError>,
    ) -> Result<T, ExecError> {
        let t = self.emitted;
        let last = self.pushed - 1;
        let extras = self
            .frames
            .iter()
            .find(|f| f.index == t)
            .and_then(|f| f.extras.as_ref());
        let (frame_aux, camera, jitter, cut) = match extras {
            Some(e) => (Some(&e.aux), e.camera, e.jitter, e.cut),
            None => (None, self.camera, [0.0, 0.0], false),
        };
        // The stream's images, and the frame's own (a rendered frame's G-buffer)
        // over them.
        let aux = self.aux.iter().chain(frame_aux.into_iter().flatten());
        let mut inputs = FrameInputs {
            frames: HashMap::new(),
            aux: aux.map(|(n, t)| (n.clone(), t.into())).collect(),
            camera,
            jitter,
            cut,
        };
        for &k in &self.offsets {
            let idx = (t as i64 + k as i64).clamp(0, last as i64) as u64;
            let tex = self
                .frames
                .iter()
                .find(|f| f.index == idx)
                .map(|f| &f.input)
                .ok_or_else(|| ExecError::Input(format!("input frame {idx} is no longer held")))?;
            inputs.frames.insert(k, tex.into());
        }
        let output = &self.output;
        let (timings, extra) =
            self.prepared
                .run_then(engine, &inputs, output, self.want_timings, |enc| {
                    then(enc, output)
                })?;
        if self.want_timings {
            self.note_timings(timings);
        }
        Ok(extra)
    }

    /// Keep a frame's timings: the last frame's, and every pass's samples (the
    /// samples restart when the passes change, as after a new plan).
    fn note_timings(&mut self, timings: Vec<PassTiming>) {
        let same = self.samples.len() == timings.len()
            && self
                .last_timings
                .iter()
                .zip(&timings)
                .all(|(a, b)| a.path == b.path);
        if !same {
            self.samples = vec![(Vec::new(), Vec::new()); timings.len()];
        }
        for (s, t) in self.samples.iter_mut().zip(&timings) {
            if let Some(g) = t.gpu_ms {
                s.0.push(g);
            }
            s.1.push(t.cpu_ms);
        }
        self.last_timings = timings;
    }
}
