//! A rendered scene in the viewer: the scene options of a normal run, rendered
//! with the camera under the mouse ([`crate::view::camera_control`]) at `--size`, or at
//! the size of the window's image area (resizing renders and plans again). The
//! effects read the render and its G-buffer (`AUX.*`), which the pass list shows
//! too.
//!
//! Time: frame n shows the scene at n / fps seconds (`--fps`, default 30), as a
//! normal run's frame n (`--time n/fps`), rendered and fed through the effect by
//! [`crate::app::SceneFrames`]: the animations' pose, the run's camera
//! (`--camera`, which may be an orbit or an animated scene camera) and the motion
//! from the previous frame time (`AUX.motion`); the effects see `frame` = n and
//! `time` = n / fps. An animated scene (or a moving `--camera`) plays (Space),
//! steps (Right, Left) and goes back to frame 0 (Home); a scripted run advances one
//! frame per frame shown. Dragging the camera leaves the run's camera (H goes back
//! to it). Temporal effects (`IN[-1]`, feedback) see each frame as a still.

use super::fx::Fx;
use crate::app::{RunError, SceneFrame, SceneFrames, SceneJob};
use crate::gpu::executor::{Engine, Prepared};
use crate::scene::Camera;
use crate::script::types::Format;
use crate::view::camera_control::CameraControl;
use crate::view::ui_state::ImageInput;
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
/// The scene, its renderer and the camera.
pub struct SceneView {
    frames: SceneFrames,
    /// The camera shown (the run's, or moved by hand).
    pub camera: Camera,
    pub control: CameraControl,
    /// `--size`: the render size does not follow the window.
    fixed: bool,
    size: (u32, u32),
    /// The camera or size changed since the last render.
    stale: bool,
    output: Option<wgpu::Texture>,
    output_format: Format,
    has_effects: bool,
    /// The `--set`s of the default chain for this scene (none for other effects).
    pub base: Vec<String>,
    pub clock: Clock,
    /// The camera was moved by hand: it no longer follows the run's camera.
    free: bool,
}

impl SceneView {
    /// Load the job's scene; `fixed`: the job's size stays (`--size` was given);
    /// the clock starts at `time` seconds and runs at `fps`.
    pub fn new(
        job: SceneJob,
        engine: &Engine,
        fixed: bool,
        output_format: Format,
        (fps, time): (f64, f64),
    ) -> Result<Self, RunError> {
        let size = (job.width, job.height);
        let has_effects = !job.effects.is_empty();
        let frames = SceneFrames::load(job, &engine.ctx)?;
        let camera = frames.home_camera();
        Ok(SceneView {
            base: frames.base_settings(),
            size,
            has_effects,
            camera,
            control: CameraControl::new(frames.radius()),
            fixed,
            stale: true,
            output: None,
            output_format,
            clock: Clock {
                frame: (time * fps).round().max(0.0) as u64,
                fps,
                playing: frames.timed(),
                last_step: Instant::now(),
            },
            free: false,
            frames,
        })
    }

    /// Does the picture change with time (an animation, a moving camera)?
    pub fn timed(&self) -> bool {
        self.frames.timed()
    }

    /// Show frame `frame` (its time frame / fps).
    pub fn set_frame(&mut self, frame: u64) {
        if self.timed() && frame != self.clock.frame {
            self.clock.frame = frame;
            self.stale = true;
        }
        self.clock.last_step = Instant::now();
    }

    /// The job (its effects and `--set`s).
    pub fn job(&self) -> &SceneJob {
        self.frames.job()
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

    /// Mouse input over an image area of `width` x `height` pixels: the render
    /// follows the area's size; drag orbits (secondary button: pans), the wheel
    /// dollies. True when the scene must be rendered again.
    pub fn apply_input(&mut self, input: &ImageInput, (width, height): (u32, u32)) -> bool {
        let resized = self.resize(width, height);
        let mut cam = self.camera;
        let mut moved = false;
        if input.drag != [0.0, 0.0] {
            let [dx, dy] = input.drag;
            if input.primary {
                self.control.orbit(&mut cam, dx, dy);
            } else {
                self.control.pan(&mut cam, dx, dy, height as f32);
            }
            moved = true;
        }
        if input.scroll != 0.0 {
            self.control.dolly(&mut cam, input.scroll);
            moved = true;
        }
        if moved {
            self.camera = cam;
            self.camera_moved();
        }
        resized || moved
    }

    /// Back to the camera of the run.
    pub fn home(&mut self) {
        self.camera = self.frames.home_camera();
        self.free = false;
        self.stale = true;
    }

    /// Plan the effect for the render size (no effect: the render is the output).
    pub fn prepare(&mut self, engine: &mut Engine, fx: &mut Fx) -> Result<(), RunError> {
        if !self.has_effects {
            return Ok(());
        }
        let effect = fx.effect_mut()?;
        let o = self
            .frames
            .prepare(engine, effect, self.size, self.output_format)?
            .plan
            .output;
        self.output = Some(crate::view::present::window_output(
            &engine.ctx,
            o.width,
            o.height,
            o.format,
        ));
        Ok(())
    }

    /// Does the plan need making for the render size?
    pub fn needs_plan(&self) -> bool {
        self.has_effects
            && self
                .frames
                .prepared()
                .is_none_or(|p| (p.plan.input.width, p.plan.input.height) != self.size)
    }

    /// The frame shown: its number, and the camera unless the run's is followed
    /// (a scene that does not change with time is seen from `camera`).
    fn scene_frame(&self) -> SceneFrame {
        SceneFrame {
            frame: self.clock.frame,
            fps: self.clock.fps,
            camera: (self.free || !self.timed()).then_some(self.camera),
        }
    }

    /// Render if the camera or size changed, then record the effect into `encoder`.
    pub fn record(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), RunError> {
        let f = self.scene_frame();
        if self.stale || self.frames.rendered().is_none() {
            let camera = self.frames.render(&engine.ctx.clone(), self.size, &f)?;
            if !self.free {
                self.camera = camera;
            }
            self.stale = false;
        }
        match &self.output {
            Some(target) => self.frames.record(engine, encoder, &f, target),
            None => Ok(()),
        }
    }

    pub fn prepared(&mut self) -> Option<&mut Prepared> {
        self.frames.prepared_mut()
    }

    pub fn prepared_ref(&self) -> Option<&Prepared> {
        self.frames.prepared()
    }

    /// The effect's output, or the render itself when there is no effect.
    pub fn output(&self) -> Option<(&wgpu::Texture, Format)> {
        if !self.has_effects {
            return self.before();
        }
        Some((
            self.output.as_ref()?,
            self.frames.prepared()?.plan.output.format,
        ))
    }

    /// The render (the effects' input).
    pub fn before(&self) -> Option<(&wgpu::Texture, Format)> {
        self.frames
            .rendered()
            .map(|(o, _)| (&o.scene, Format::Rgba16f))
    }

    /// The G-buffer images the effects read as `AUX.*`.
    pub fn aux(&self) -> Vec<(String, &wgpu::Texture, Format)> {
        self.frames.aux_images()
    }

    /// Near and far of the camera (the range depth is shown in).
    pub fn depth_range(&self) -> (f32, f32) {
        (self.camera.near, self.camera.far)
    }

    /// The scene, the render size and technique, and the frame when timed.
    pub fn caption(&self) -> String {
        let time = if self.timed() {
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
            self.job().scene,
            self.size.0,
            self.size.1,
            self.job().technique
        )
    }
}
