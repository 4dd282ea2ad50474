//! A scene rendered frame by frame and fed through an effect chain, for an
//! application that shows a scene live (`fxrun --view` uses it, as an embedder
//! would): [`SceneFrames`] owns the loaded scene and its renderer, renders a frame
//! for a time and a camera ([`SceneFrames::render`]: the animations' pose, the
//! run's camera path, the motion since the previous frame time, the sub-pixel
//! jitter of the effect) and records the effect over that render into the
//! caller's encoder ([`SceneFrames::record`]), the G-buffer as the effect's
//! `AUX.*` images. The render, its AUX images and the render's statistics stay
//! readable ([`SceneFrames::rendered`]).
//!
//! Frame n of a run at `fps` is the scene at n / fps seconds, as a normal scene
//! run's frame n (`--time n/fps`).

use super::scene::{default_chain_settings, load_scene, render_error, scene_renderer, SceneJob};
use super::{Effect, RunError};
use crate::gpu::context::GpuContext;
use crate::gpu::executor::{Engine, FrameInputs, Prepared};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::render::renderer::Renderer;
use crate::render::{FrameMotion, RenderError, RenderOutput, RenderStats};
use crate::scene::{Camera, CameraPath, Playback, Pose, Scene};
use crate::script::types::Format;

/// Which frame to render, and from where.
#[derive(Debug, Clone, Copy)]
pub struct SceneFrame {
    /// The frame number; its time is `frame / fps` seconds.
    pub frame: u64,
    pub fps: f64,
    /// A camera of the caller's (moved by hand); `None`: the run's camera at the
    /// frame's time (`SceneJob::camera`, which may move).
    pub camera: Option<Camera>,
}

/// A loaded scene, its renderer, the last render and the effect planned for it.
pub struct SceneFrames {
    job: SceneJob,
    scene: Scene,
    renderer: Renderer,
    path: CameraPath,
    playback: Playback,
    /// The run's camera when the scene was loaded.
    home: Camera,
    /// Animated, or seen from a moving camera: the frame's time matters.
    timed: bool,
    rendered: Option<(RenderOutput, RenderStats)>,
    /// The sub-pixel jitter the render was made with.
    jitter: [f32; 2],
    prepared: Option<Prepared>,
    /// The job's own auxiliary images (`--aux`, a slang preset's LUTs), on the GPU.
    job_aux: super::scene::JobAux,
}

impl SceneFrames {
    /// Load the job's scene (its materials, animation and camera path) and make
    /// its renderer on `ctx`.
    pub fn load(job: SceneJob, ctx: &GpuContext) -> Result<Self, RunError> {
        let (scene, home) = load_scene(&job)?;
        let scene_error = |e| render_error(&job.scene, RenderError::Scene(e));
        let path = CameraPath::parse(job.camera.as_deref(), &scene).map_err(scene_error)?;
        let playback = match &job.animation {
            Some(spec) => Playback::parse(spec, &scene, job.looping).map_err(scene_error)?,
            None => Playback {
                looping: job.looping,
                ..Playback::default()
            },
        };
        let timed = scene.is_animated() || !matches!(path, CameraPath::Fixed(_));
        let renderer = scene_renderer(&job, ctx, &scene)?;
        let job_aux = super::scene::upload_job_aux(&job, ctx)?;
        Ok(SceneFrames {
            job,
            scene,
            renderer,
            path,
            playback,
            home,
            timed,
            rendered: None,
            jitter: [0.0, 0.0],
            prepared: None,
            job_aux,
        })
    }

    /// The job (its effects, `--set`s, size and technique).
    pub fn job(&self) -> &SceneJob {
        &self.job
    }

    /// The run's camera when the scene was loaded.
    pub fn home_camera(&self) -> Camera {
        self.home
    }

    /// Does the picture change with time (an animation, a moving camera)?
    pub fn timed(&self) -> bool {
        self.timed
    }

    /// Half the diagonal of the scene's bounds (1 for an empty scene).
    pub fn radius(&self) -> f32 {
        let b = self.scene.bounds();
        if b.is_empty() {
            1.0
        } else {
            (b.max - b.min).length() * 0.5
        }
    }

    /// The `--set`s of the default chain for this scene (none when the job's
    /// effects are not the default chain).
    pub fn base_settings(&self) -> Vec<String> {
        if self.job.default_chain && !self.job.effects.is_empty() {
            default_chain_settings(&self.scene)
        } else {
            Vec::new()
        }
    }

    /// The G-buffer images a render gives (`AUX.*`), with their formats.
    pub fn aux_formats(&self) -> &[(String, Format)] {
        self.renderer.aux_formats()
    }

    /// What an effect over a `width` x `height` render reads: the G-buffer
    /// and the job's own auxiliary images.
    pub fn input_desc(&self, (width, height): (u32, u32)) -> InputDesc {
        SceneJob {
            width,
            height,
            ..self.job.clone()
        }
        .effect_input(&self.renderer, &self.job_aux)
    }

    /// Plan `effect` for renders of `size` with output `output_format` (pooled
    /// textures, GPU times on); the pass inspected before stays inspected.
    pub fn prepare(
        &mut self,
        engine: &mut Engine,
        effect: &mut Effect,
        size: (u32, u32),
        output_format: Format,
    ) -> Result<&Prepared, RunError> {
        let opts = PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(output_format),
        };
        let mut prepared = effect.prepare_with(engine, &self.input_desc(size), &opts)?;
        let inspect = self.prepared.as_ref().and_then(|p| p.inspected_pass());
        if inspect.is_some_and(|i| i < prepared.plan.passes.len()) {
            let _ = prepared.inspect(inspect);
        }
        prepared.set_gpu_timings(engine, true);
        Ok(self.prepared.insert(prepared))
    }

    /// The pose and the run's camera at `t` seconds.
    fn at(&self, t: f64) -> (Pose, Camera) {
        let pose = self.scene.pose(t, &self.playback);
        let camera = self.path.at(&self.scene, Some(&pose), t);
        (pose, camera)
    }

    /// The camera, the motion since the previous frame time and the jitter of
    /// frame `f`; the lights of an animated scene move to the frame's pose.
    fn frame_motion(&mut self, f: &SceneFrame) -> (Camera, FrameMotion) {
        let t = f.frame as f64 / f.fps;
        let (pose, run_camera) = self.at(t);
        let (prev, prev_run_camera) = self.at(t - 1.0 / f.fps);
        let (camera, prev_camera) = match f.camera {
            Some(c) => (c, c),
            None => (run_camera, prev_run_camera),
        };
        if self.scene.is_animated() {
            self.renderer.set_lights(pose.lights.clone());
        }
        let jitter = self
            .prepared
            .as_ref()
            .and_then(|p| p.jitter())
            .map_or([0.0, 0.0], |p| p.offset(f.frame));
        let motion = FrameMotion {
            prev_camera: Some(prev_camera),
            jitter,
            ..FrameMotion::posed(&self.scene, &pose, &prev)
        };
        (camera, motion)
    }

    /// Render frame `f` at `width` x `height`; returns the camera it was seen
    /// from. A scene that does not change with time is rendered from `f.camera`
    /// (else the run's first camera), without motion.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        (width, height): (u32, u32),
        f: &SceneFrame,
    ) -> Result<Camera, RunError> {
        let technique = self.job.technique;
        let (camera, rendered) = if self.timed {
            let (camera, motion) = self.frame_motion(f);
            self.jitter = motion.jitter;
            let r = self
                .renderer
                .render_frame(ctx, &camera, &motion, width, height, technique, None);
            (camera, r)
        } else {
            let camera = f.camera.unwrap_or(self.home);
            let r = self
                .renderer
                .render(ctx, &camera, width, height, technique, None);
            (camera, r)
        };
        let rendered = rendered.map_err(|e| render_error(&self.job.scene, e))?;
        self.rendered = Some(rendered);
        Ok(camera)
    }

    /// Record the planned effect over the last render into `encoder`, as frame
    /// `f.frame` at `f.fps`, writing `target` (in the plan's output format).
    pub fn record(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
        f: &SceneFrame,
        target: &wgpu::Texture,
    ) -> Result<(), RunError> {
        let (Some((out, _)), Some(p)) = (&self.rendered, &mut self.prepared) else {
            return Ok(());
        };
        if (out.width, out.height) != (p.plan.input.width, p.plan.input.height) {
            return Err(RunError::Other(
                "the render and the plan differ in size".into(),
            ));
        }
        p.frame = f.frame;
        p.fps = f.fps;
        let mut inputs = FrameInputs::still(&out.scene, &p.plan);
        inputs.jitter = self.jitter;
        inputs.aux = out.aux.iter().map(|(n, t)| (n.clone(), t.into())).collect();
        inputs
            .aux
            .extend(self.job_aux.iter().map(|(n, t, ..)| (n.clone(), t.into())));
        inputs.camera = Some(out.camera);
        Ok(p.record(engine, encoder, &inputs, target)?)
    }

    /// The last render and its statistics.
    pub fn rendered(&self) -> Option<&(RenderOutput, RenderStats)> {
        self.rendered.as_ref()
    }

    /// The render's G-buffer images (`AUX.*`), with their formats.
    pub fn aux_images(&self) -> Vec<(String, &wgpu::Texture, Format)> {
        let Some((out, _)) = &self.rendered else {
            return Vec::new();
        };
        let formats = self.aux_formats();
        out.aux
            .iter()
            .map(|(n, t)| {
                let f = formats
                    .iter()
                    .find(|(m, _)| m == n)
                    .map_or(Format::Rgba16f, |(_, f)| *f);
                (n.clone(), t, f)
            })
            .collect()
    }

    /// The effect planned by [`SceneFrames::prepare`].
    pub fn prepared(&self) -> Option<&Prepared> {
        self.prepared.as_ref()
    }

    /// The effect planned, to set parameters or inspect a pass.
    pub fn prepared_mut(&mut self) -> Option<&mut Prepared> {
        self.prepared.as_mut()
    }
}
