//! A rendered scene in the viewer: the scene options of a normal run, rendered
//! with the camera under the mouse ([`super::camera_control`]) at `--size`, or at
//! the size of the window's image area (resizing renders and plans again). The
//! effects read the render and its G-buffer (`AUX.*`), which the pass list shows
//! too. The scene model has no clock yet: the picture changes when the camera does.

use super::camera_control::CameraControl;
use super::fx::Fx;
use fxgraph::app::scene::{load_scene, render_error, scene_renderer, SceneJob};
use fxgraph::app::RunError;
use fxgraph::gpu::executor::{Engine, ExecError, FrameInputs, Prepared};
use fxgraph::graph::plan::{InputDesc, PlanOptions, ReusePolicy};
use fxgraph::render::renderer::Renderer;
use fxgraph::render::RenderOutput;
use fxgraph::scene::Camera;
use fxgraph::script::types::{ColorSpace, Format};

/// The scene, its renderer and the camera.
pub(super) struct SceneView {
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
}

impl SceneView {
    /// Load the job's scene; `fixed`: the job's size stays (`--size` was given).
    pub fn new(
        job: SceneJob,
        engine: &Engine,
        fixed: bool,
        output_format: Format,
    ) -> Result<Self, RunError> {
        let (scene, camera) = load_scene(&job)?;
        let b = scene.bounds();
        let radius = if b.is_empty() {
            1.0
        } else {
            (b.max - b.min).length() * 0.5
        };
        let renderer = scene_renderer(&job, &engine.ctx, &scene)?;
        let base = if job.default_chain && !job.effects.is_empty() {
            fxgraph::app::scene::default_chain_settings(&scene)
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
        })
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

    /// The camera moved: render again.
    pub fn camera_moved(&mut self) {
        self.stale = true;
    }

    /// Back to the camera of the run.
    pub fn home(&mut self) {
        self.camera = self.home;
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
        let dropped = fx.after_prepare(&mut prepared);
        if !dropped.is_empty() {
            log::info!("parameters no longer in the effect: {}", dropped.join(", "));
        }
        let inspect = self.prepared.as_ref().and_then(|p| p.inspected_pass());
        if inspect.is_some_and(|i| i < prepared.plan.passes.len()) {
            let _ = prepared.inspect(inspect);
        }
        prepared.set_gpu_timings(engine, true);
        let o = prepared.plan.output;
        self.output = Some(super::present::window_output(
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
            let (out, _) = self
                .renderer
                .render(
                    &ctx,
                    &self.camera,
                    self.size.0,
                    self.size.1,
                    self.job.technique,
                    None,
                )
                .map_err(|e| render_error(&self.job.scene, e))?;
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
        p.frame = 0;
        let mut inputs = FrameInputs::still(&out.scene, &p.plan);
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
        format!(
            "{} ({}x{}, {})",
            self.job.scene, self.size.0, self.size.1, self.job.technique
        )
    }
}
