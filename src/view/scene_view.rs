//! A rendered scene in the viewer: the scene options of a normal run, rendered
//! with the camera under the mouse ([`crate::view::camera_control`]) at `--size`, or at
//! the size of the window's image area (resizing renders and plans again). The
//! effects read the render and its G-buffer (`AUX.*`), which the pass list shows
//! too.
//!
//! Time: frame n shows the scene at n / fps seconds (`--fps`, default 30), as a
//! normal run's frame n (`--time n/fps`): the animations' pose, the run's camera
//! (`--camera`, which may be an orbit or an animated scene camera) and the motion
//! from the previous frame time (`AUX.motion`); the effects see `frame` = n and
//! `time` = n / fps. An animated scene (or a moving `--camera`) plays (Space),
//! steps (Right, Left) and goes back to frame 0 (Home); a scripted run advances one
//! frame per frame shown. Dragging the camera leaves the run's camera (H goes back
//! to it). Temporal effects (`IN[-1]`, feedback) see each frame as a still.

use super::fx::Fx;
use crate::app::scene::{load_scene, render_error, scene_renderer, SceneJob};
use crate::app::RunError;
use crate::gpu::executor::{Engine, ExecError, FrameInputs, Prepared};
use crate::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use crate::render::renderer::Renderer;
use crate::render::{FrameMotion, RenderOutput};
use crate::scene::{Camera, CameraPath, Playback, Pose, Scene};
use crate::view::camera_control::CameraControl;
use std::time::{Duration, Instant};

/// The scene's clock.
pub struct Clock {
    pub frame: u64,
    pub fps: f64,
    pub playing: bool,
    last_step: Instant,
}

impl Clock {
    /// Is the next frame due (playing at `fps`)?
    pub fn due(&self) -> bool {
        self.playing && self.last_step.elapsed() >= self.period()
    }

    /// Time until the next frame is due, when playing.
    pub fn until_due(&self) -> Option<Duration> {
        self.playing
            .then(|| self.period().saturating_sub(self.last_step.elapsed()))
    }

    fn period(&self) -> Duration {
        Duration::from_secs_f64(1.0 / self.fps)
    }
}
use crate::script::types::{ColorSpace, Format};

/// The scene, its renderer and the camera.
pub struct SceneView {
    job: SceneJob,
    renderer: Renderer,
    pub camera: Camera,
    home: Camera,
    pub control: CameraControl,
    /// `--size`: the render size does not follow the window.
    fixed: bool,
    size: (u32, u32),
    rendered: Option<RenderOutput>,
    /// The camera or size changed since the last render.
    stale: bool,
    prepared: Option<Prepared>,
    output: Option<wgpu::Texture>,
    output_format: Format,
    has_effects: bool,
    /// The `--set`s of the default chain for this scene (none for other effects).
    pub base: Vec<String>,
    scene: Scene,
    path: CameraPath,
    playback: Playback,
    /// Animated, or seen from a moving camera: the clock matters.
    timed: bool,
    pub clock: Clock,
    /// The camera was moved by hand: it no longer follows the run's camera.
    free: bool,
    /// The sub-pixel jitter the render was made with.
    rendered_jitter: [f32; 2],
}

impl SceneView {
    /// Load the job's scene; `fixed`: the job's size stays (`--size` was given).
    pub fn new(
        job: SceneJob,
        engine: &Engine,
        fixed: bool,
        output_format: Format,
        (fps, time): (f64, f64),
    ) -> Result<Self, RunError> {
        let (scene, camera) = load_scene(&job)?;
        let scene_error = |e| render_error(&job.scene, crate::render::RenderError::Scene(e));
        let path = CameraPath::parse(job.camera.as_deref(), &scene).map_err(scene_error)?;
        let playback = match &job.animation {
            Some(spec) => Playback::parse(spec, &scene, job.looping).map_err(scene_error)?,
            None => Playback {
                looping: job.looping,
                ..Playback::default()
            },
        };
        let timed = scene.is_animated() || !matches!(path, CameraPath::Fixed(_));
        let b = scene.bounds();
        let radius = if b.is_empty() {
            1.0
        } else {
            (b.max - b.min).length() * 0.5
        };
        let renderer = scene_renderer(&job, &engine.ctx, &scene)?;
        let base = if job.default_chain && !job.effects.is_empty() {
            crate::app::scene::default_chain_settings(&scene)
        } else {
            Vec::new()
        };
        Ok(SceneView {
            base,
            size: (job.width, job.height),
            has_effects: !job.effects.is_empty(),
            job,
            renderer,
            home: camera,
            camera,
            control: CameraControl::new(radius),
            fixed,
            rendered: None,
            stale: true,
            prepared: None,
            output: None,
            output_format,
            scene,
            path,
            playback,
            timed,
            clock: Clock {
                frame: (time * fps).round().max(0.0) as u64,
                fps,
                playing: timed,
                last_step: Instant::now(),
            },
            free: false,
            rendered_jitter: [0.0, 0.0],
        })
    }

    /// Does the picture change with time (an animation, a moving camera)?
    pub fn timed(&self) -> bool {
        self.timed
    }

    /// Show frame `frame` (its time frame / fps).
    pub fn set_frame(&mut self, frame: u64) {
        if self.timed && frame != self.clock.frame {
            self.clock.frame = frame;
            self.stale = true;
        }
        self.clock.last_step = Instant::now();
    }

    /// The pose and the run's camera at `t` seconds.
    fn at(&self, t: f64) -> (Pose, Camera) {
        let pose = self.scene.pose(t, &self.playback);
        let camera = self.path.at(&self.scene, Some(&pose), t);
        (pose, camera)
    }

    /// The camera, the motion since the previous frame time and the jitter of the
    /// frame shown.
    fn frame_motion(&mut self) -> (Camera, FrameMotion) {
        let fps = self.clock.fps;
        let t = self.clock.frame as f64 / fps;
        let (pose, run_camera) = self.at(t);
        let (prev, prev_run_camera) = self.at(t - 1.0 / fps);
        let (camera, prev_camera) = if self.free {
            (self.camera, self.camera)
        } else {
            (run_camera, prev_run_camera)
        };
        if self.scene.is_animated() {
            // lights on animated nodes move with them
            self.renderer.set_lights(pose.lights.clone());
        }
        let jitter = self
            .prepared
            .as_ref()
            .and_then(|p| p.jitter())
            .map_or([0.0, 0.0], |p| p.offset(self.clock.frame));
        let motion = FrameMotion {
            prev_camera: Some(prev_camera),
            jitter,
            ..FrameMotion::posed(&self.scene, &pose, &prev)
        };
        (camera, motion)
    }

    /// The job (its effects and `--set`s).
    pub fn job(&self) -> &SceneJob {
        &self.job
    }

    /// Follow the window's image area (unless `--size` was given); true when the
    /// render size changed (the effect must be planned again).
    pub fn resize(&mut self, width: u32, height: u32) -> bool {
        let (w, h) = (width.max(16), height.max(16));
        if self.fixed || (w, h) == self.size {
            return false;
        }
        self.size = (w, h);
        self.stale = true;
        true
    }

    /// The camera moved by hand: render again, from now on from this camera.
    pub fn camera_moved(&mut self) {
        self.free = true;
        self.stale = true;
    }

    /// Back to the camera of the run.
    pub fn home(&mut self) {
        self.camera = self.home;
        self.free = false;
        self.stale = true;
    }

    /// Plan the effect for the render size (no effect: the render is the output).
    pub fn prepare(&mut self, engine: &mut Engine, fx: &mut Fx) -> Result<(), RunError> {
        if !self.has_effects {
            return Ok(());
        }
        let desc = InputDesc {
            width: self.size.0,
            height: self.size.1,
            format: Format::Rgba16f,
            colorspace: ColorSpace::Linear,
            aux: self.renderer.aux_formats().to_vec(),
        };
        let opts = PlanOptions {
            policy: ReusePolicy::Pool,
            output_format: Some(self.output_format),
        };
        let mut prepared = fx.effect_mut()?.prepare_with(engine, &desc, &opts)?;
        let inspect = self.prepared.as_ref().and_then(|p| p.inspected_pass());
        if inspect.is_some_and(|i| i < prepared.plan.passes.len()) {
            let _ = prepared.inspect(inspect);
        }
        prepared.set_gpu_timings(engine, true);
        let o = prepared.plan.output;
        self.output = Some(crate::view::present::window_output(
            &engine.ctx,
            o.width,
            o.height,
            o.format,
        ));
        self.prepared = Some(prepared);
        Ok(())
    }

    /// Does the plan need making for the render size?
    pub fn needs_plan(&self) -> bool {
        self.has_effects
            && self
                .prepared
                .as_ref()
                .is_none_or(|p| (p.plan.input.width, p.plan.input.height) != self.size)
    }

    /// Render if the camera or size changed, then record the effect into `encoder`.
    pub fn record(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), RunError> {
        if self.stale || self.rendered.is_none() {
            let ctx = engine.ctx.clone();
            let rendered = if self.timed {
                let (camera, motion) = self.frame_motion();
                self.rendered_jitter = motion.jitter;
                if !self.free {
                    self.camera = camera;
                }
                self.renderer.render_frame(
                    &ctx,
                    &camera,
                    &motion,
                    self.size.0,
                    self.size.1,
                    self.job.technique,
                    None,
                )
            } else {
                self.renderer.render(
                    &ctx,
                    &self.camera,
                    self.size.0,
                    self.size.1,
                    self.job.technique,
                    None,
                )
            };
            let (out, _) = rendered.map_err(|e| render_error(&self.job.scene, e))?;
            self.rendered = Some(out);
            self.stale = false;
        }
        let (Some(out), Some(p), Some(target)) = (&self.rendered, &mut self.prepared, &self.output)
        else {
            return Ok(());
        };
        if (out.width, out.height) != (p.plan.input.width, p.plan.input.height) {
            return Err(RunError::Other(
                "the render and the plan differ in size".into(),
            ));
        }
        p.frame = self.clock.frame;
        p.fps = self.clock.fps;
        let mut inputs = FrameInputs::still(&out.scene, &p.plan);
        inputs.jitter = self.rendered_jitter;
        inputs.aux = out.aux.iter().map(|(n, t)| (n.clone(), t.into())).collect();
        inputs.camera = Some(out.camera);
        p.record(engine, encoder, &inputs, target)
            .map_err(|e: ExecError| RunError::from(e))
    }

    pub fn prepared(&mut self) -> Option<&mut Prepared> {
        self.prepared.as_mut()
    }

    pub fn prepared_ref(&self) -> Option<&Prepared> {
        self.prepared.as_ref()
    }

    /// The effect's output, or the render itself when there is no effect.
    pub fn output(&self) -> Option<(&wgpu::Texture, Format)> {
        if !self.has_effects {
            return self.rendered.as_ref().map(|o| (&o.scene, Format::Rgba16f));
        }
        Some((
            self.output.as_ref()?,
            self.prepared.as_ref()?.plan.output.format,
        ))
    }

    /// The render (the effects' input).
    pub fn before(&self) -> Option<(&wgpu::Texture, Format)> {
        self.rendered.as_ref().map(|o| (&o.scene, Format::Rgba16f))
    }

    /// The G-buffer images the effects read as `AUX.*`, with the camera's range.
    pub fn aux(&self) -> Vec<(String, &wgpu::Texture, Format)> {
        let Some(out) = &self.rendered else {
            return Vec::new();
        };
        let formats = self.renderer.aux_formats();
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

    /// Near and far of the camera (the range depth is shown in).
    pub fn depth_range(&self) -> (f32, f32) {
        (self.camera.near, self.camera.far)
    }

    pub fn caption(&self) -> String {
        let time = if self.timed {
            let c = &self.clock;
            let state = if c.playing { "playing" } else { "paused" };
            format!(
                ", frame {} at {:.3} s ({state})",
                c.frame,
                c.frame as f64 / c.fps
            )
        } else {
            String::new()
        };
        format!(
            "{} ({}x{}, {}){time}",
            self.job.scene, self.size.0, self.size.1, self.job.technique
        )
    }
}
