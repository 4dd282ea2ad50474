//! `fxrun EFFECT... --scene SCENE -o OUT`: render a scene with the deferred
//! renderer and run an effect chain on it, with the G-buffer as `AUX.*` inputs and
//! the camera as the standard values `near`, `far`, `proj`, `inv_proj`.

use super::effect::Effect;
use super::error::RunError;
use super::report::{ms, FrameDone, JobKind, MemoryReport, RunReport, SceneStats};
pub use super::scene_errors::render_error;
pub(super) use super::scene_errors::{environment_error, scene_error};
use super::still::output_format_for;
use crate::gpu::executor::{Engine, FrameInputs};
use crate::gpu::transfer::{create_output, read_pixels};
use crate::graph::plan::InputDesc;
use crate::io::{self, IoError, SaveOptions};
use crate::render::renderer::{RenderStats, Renderer, RendererOptions, Technique};
use crate::render::RenderOutput;
use crate::scene::{Camera, Scene};
use crate::script::types::{ColorSpace, Format};
use std::path::PathBuf;
use std::time::Instant;

/// The effect chain of `fxrun -o OUT` with no effect and no input: the built-in
/// scene through SSAO, fog, glow, tone mapping and FXAA.
pub const DEFAULT_CHAIN: [&str; 5] = ["ssao", "fog", "glow", "tonemap", "fxaa"];

/// Settings of the default chain for a scene (a user's `--set` comes after them
/// and wins): the fog's density scaled to the scene, so that light crossing the
/// scene's bounding-box diagonal keeps exp(-0.2) ≈ 82 % of its colour, whatever
/// the scene's units (the built-in room: 0.01 per unit; a Cornell box modelled
/// in millimetres would otherwise vanish in the fog).
pub fn default_chain_settings(scene: &Scene) -> Vec<String> {
    let b = scene.bounds();
    let diagonal = if b.is_empty() {
        20.0
    } else {
        (b.max - b.min).length().max(1e-6)
    };
    vec![format!("fog.density={}", 0.2 / diagonal)]
}

/// What to render and where to write it.
#[derive(Debug, Clone)]
pub struct SceneJob {
    /// `builtin:room`, `builtin:bench` or a `.gltf`/`.glb` path.
    pub scene: String,
    pub width: u32,
    pub height: u32,
    /// A camera spec (see [`Camera::parse_spec`], and for sequences
    /// [`crate::scene::CameraPath::parse`]); `None`: the scene's first camera or a
    /// framing of its bounds.
    pub camera: Option<String>,
    /// `--animation`: which animations play (`all`, `none`, an index or a name;
    /// `None`: all), and whether they loop.
    pub animation: Option<String>,
    pub looping: bool,
    /// Random point lights to add, and their seed.
    pub lights: usize,
    pub seed: u64,
    pub technique: Technique,
    /// Effects to run (empty: write the rendered scene itself).
    pub effects: Vec<String>,
    pub overrides: Vec<crate::graph::Override>,
    /// `effects` is the default chain: its settings are scaled to the scene
    /// ([`default_chain_settings`]) before `overrides`.
    pub default_chain: bool,
    pub output: Option<PathBuf>,
    pub bit_depth: Option<u8>,
    /// Write every G-buffer image into this folder.
    pub gbuffer: Option<PathBuf>,
    pub timings: bool,
    /// A file of `MATERIAL` definitions: those named like a scene material
    /// replace it.
    pub materials: Option<PathBuf>,
    /// `SCENE_MATERIAL=DEFINITION` pairs (`*` for every scene material).
    pub material_map: Vec<(String, String)>,
    /// How material features select shader code.
    pub variants: crate::render::material::VariantMode,
    /// How the light passes pick each pixel's lights.
    pub light_culling: crate::render::renderer::LightCulling,
    /// How deferred shading fills the G-buffer (`--gbuffer-layout`).
    pub gbuffer_layout: crate::render::GbufferLayout,
    /// Fog applied in the lighting template (no post pass).
    pub fog: Option<crate::render::fog::Fog>,
    /// Print each material, its shaders and variant, and the pipelines compiled.
    pub describe_materials: bool,
    /// An ambient light to add (linear RGB radiance); scenes otherwise render
    /// only the lights they have.
    pub ambient: Option<[f32; 3]>,
    /// Shadow maps: filter (or off), map size, layers per frame.
    pub shadows: crate::render::shadows::ShadowMode,
    pub shadow_size: u32,
    pub shadow_layers: u32,
    /// Image-based lighting (`None`: the scene's punctual lights only), see
    /// [`crate::scene::Environment`].
    pub environment: Option<crate::scene::Environment>,
    /// What pixels without geometry show (`None`: the scene's colour).
    pub background: Option<crate::scene::Background>,
    /// Auxiliary images beside the renderer's (`--aux NAME=FILE`, a slang
    /// preset's LUTs), each at its own size, the same for every frame.
    pub aux: Vec<(String, PathBuf)>,
}

/// The job's own auxiliary images, on the GPU: name, texture, format, size.
pub(super) type JobAux = Vec<(String, wgpu::Texture, Format, (u32, u32))>;

/// Decodes and uploads the job's `aux` images once for the run.
pub(super) fn upload_job_aux(
    job: &SceneJob,
    ctx: &crate::gpu::context::GpuContext,
) -> Result<JobAux, RunError> {
    let images = super::sources::load_aux(&job.aux, &crate::io::LoadOptions::default())?;
    images
        .iter()
        .map(|(name, img)| {
            let format = crate::gpu::transfer::input_format(img, false).0;
            let tex = crate::gpu::transfer::upload_image(ctx, &format!("aux {name}"), img, format)?;
            Ok((name.clone(), tex, format, (img.width, img.height)))
        })
        .collect()
}

impl SceneJob {
    /// The statistics of a run of this job before anything is measured: what
    /// it renders and how.
    pub(super) fn initial_stats(&self) -> SceneStats {
        SceneStats {
            scene: self.scene.clone(),
            technique: self.technique.to_string(),
            light_culling: self.light_culling.to_string(),
            gbuffer_layout: self.gbuffer_layout.to_string(),
            shadows: self.shadows.to_string(),
            ..Default::default()
        }
    }

    /// What the effects get from a frame this job renders: linear rgba16f at the
    /// render size, with the renderer's auxiliary images and the job's own
    /// (`job_aux`, at their sizes).
    pub(super) fn effect_input(&self, renderer: &Renderer, job_aux: &JobAux) -> InputDesc {
        let mut aux = renderer.aux_formats().to_vec();
        aux.retain(|(n, _)| !job_aux.iter().any(|(j, ..)| j == n));
        aux.extend(job_aux.iter().map(|(n, _, f, _)| (n.clone(), *f)));
        InputDesc {
            width: self.width,
            height: self.height,
            format: Format::Rgba16f,
            colorspace: ColorSpace::Linear,
            aux,
            aux_sizes: job_aux.iter().map(|(n, _, _, s)| (n.clone(), *s)).collect(),
            viewport: None,
        }
    }
}

/// Everything a scene job does before rendering: the user's input checked (the
/// size, the effect compiled first so that script errors come first), the scene
/// loaded with its materials, lights and ambient, the renderer made. Shared by
/// stills ([`run_scene_job`]) and rendered sequences (`scene_sequence.rs`).
pub(super) fn prepare(
    job: &SceneJob,
    engine: &mut Engine,
    stats: &mut SceneStats,
) -> Result<(Scene, Renderer, Option<Effect>), RunError> {
    // Check everything the user wrote before rendering.
    let max = engine.ctx.device.limits().max_texture_dimension_2d;
    if job.width.max(job.height) > max {
        return Err(RunError::BadInput(IoError::Unsupported {
            path: PathBuf::from(&job.scene),
            message: format!(
                "the render size {}x{} is larger than the GPU's limit of {max} pixels per side",
                job.width, job.height
            ),
        }));
    }
    // (compiled before the scene loads, so that script errors come first; the
    // default chain needs the scene's scale and is compiled after it)
    let mut effect = if job.effects.is_empty() || job.default_chain {
        None
    } else {
        Some(Effect::compile_overrides(
            &job.effects,
            job.overrides.clone(),
        )?)
    };
    let t = Instant::now();
    let (scene, _) = load_scene(job)?;
    if job.default_chain && !job.effects.is_empty() {
        let mut overrides = crate::graph::Override::parse_all(&default_chain_settings(&scene));
        overrides.extend(job.overrides.iter().cloned());
        effect = Some(Effect::compile_overrides(&job.effects, overrides)?);
    }
    stats.load_ms = ms(t.elapsed());
    let renderer = scene_renderer(job, &engine.ctx, &scene)?;
    // the fat G-buffer where the adapter cannot have a visibility buffer
    if renderer.visibility_fallback_batches().is_none() {
        stats.gbuffer_layout = crate::render::GbufferLayout::Fat.to_string();
    }
    Ok((scene, renderer, effect))
}

/// Load the job's scene with its `--materials`, random lights, ambient light and
/// environment, and the camera it is seen from at time 0 (the job's `--camera`,
/// an orbit's start, or the scene's default).
pub fn load_scene(job: &SceneJob) -> Result<(Scene, Camera), RunError> {
    let mut scene = Scene::load(&job.scene).map_err(|e| scene_error(&job.scene, e))?;
    if let Some(path) = &job.materials {
        // A regular file of at most 1 MiB (`--materials /dev/zero` would never end).
        let bytes = crate::io::read_regular_file(path, crate::shader::include::MAX_INCLUDE_BYTES)
            .map_err(RunError::from)?;
        let text = String::from_utf8(bytes).map_err(|_| {
            RunError::BadInput(IoError::Decode {
                path: path.clone(),
                message: "not a text file (invalid UTF-8)".into(),
            })
        })?;
        let rejected = |rendered: String| RunError::Rejected { rendered };
        let file = crate::scene::material_file::load_materials(
            &path.display().to_string(),
            &text,
            path.parent(),
            scene.textures.len(),
        )
        .map_err(rejected)?;
        let replaced =
            crate::scene::material_file::apply_materials(&mut scene, file, &job.material_map)
                .map_err(|m| rejected(format!("{m}\n")))?;
        log::info!(
            "{}: materials replaced: {}",
            path.display(),
            replaced.join(", ")
        );
    } else if !job.material_map.is_empty() {
        return Err(RunError::Rejected {
            rendered: "--material needs --materials FILE (the file that defines them)\n".into(),
        });
    }
    if job.lights > 0 {
        scene.add_random_point_lights(job.lights, job.seed);
    }
    if let Some([r, g, b]) = job.ambient {
        scene.lights.push(crate::scene::Light {
            name: "--ambient".into(),
            ..crate::scene::Light::ambient(glam::Vec3::new(r, g, b), 1.0)
        });
    }
    scene.ensure_lights();
    if let Some(env) = &job.environment {
        if let crate::scene::EnvironmentSource::Sky(sky) = &env.source {
            sky.check()
                .map_err(|m| environment_error(crate::scene::EnvironmentError::Spec(m)))?;
        }
        scene.set_environment(Some(env.clone()));
    }
    // a scene camera named like a keyword (`orbit`): said once per job
    if let Some(w) = job
        .camera
        .as_deref()
        .and_then(|spec| crate::scene::camera_path::shadowed_camera(spec, &scene))
    {
        log::warn!("{}: {w}", job.scene);
    }
    let camera = crate::scene::CameraPath::parse(job.camera.as_deref(), &scene)
        .map_err(|e| scene_error(&job.scene, e))?
        .at(&scene, None, 0.0);
    Ok((scene, camera))
}

/// The renderer of a loaded scene with the job's options (technique-independent:
/// variants, light culling, shadows, fog, background).
pub fn scene_renderer(
    job: &SceneJob,
    ctx: &crate::gpu::context::GpuContext,
    scene: &Scene,
) -> Result<Renderer, RunError> {
    let mut renderer = Renderer::new(
        ctx,
        scene,
        &RendererOptions {
            variants: job.variants,
            light_culling: job.light_culling,
            gbuffer_layout: job.gbuffer_layout,
            shadows: job.shadows,
            shadow_size: job.shadow_size,
            shadow_budget: job.shadow_layers,
            ..Default::default()
        },
    )
    .map_err(|e| render_error(&job.scene, e))?;
    renderer.set_fog(job.fog);
    if let Some(b) = job.background {
        renderer.set_background(b);
    }
    Ok(renderer)
}

/// Render the scene, run the effects, write the output (and the G-buffer).
pub fn run_scene_job(job: &SceneJob, engine: &mut Engine) -> Result<RunReport, RunError> {
    let t_all = Instant::now();
    let mut report = RunReport {
        job: JobKind::Scene,
        adapter: engine.ctx.info.name.clone(),
        backend: format!("{:?}", engine.ctx.info.backend),
        frames_total: Some(1),
        ..Default::default()
    };
    let mut stats = job.initial_stats();
    let out_format = match &job.output {
        Some(p) => Some(output_format_for(p, job.bit_depth, false)?),
        None => None,
    };
    let (scene, mut renderer, mut effect) = prepare(job, engine, &mut stats)?;
    let ctx = engine.ctx.clone();
    // a still is the camera path at time 0 (an orbit's start, a scene camera in
    // its rest pose, a fixed `eye=...`, or the scene's default)
    let camera = crate::scene::CameraPath::parse(job.camera.as_deref(), &scene)
        .map_err(|e| scene_error(&job.scene, e))?
        .at(&scene, None, 0.0);
    let timer = if job.timings {
        crate::gpu::context::GpuTimer::new(&ctx, 64)
    } else {
        None
    };
    let (out, rs): (_, RenderStats) = renderer
        .render(
            &ctx,
            &camera,
            job.width,
            job.height,
            job.technique,
            timer.as_ref(),
        )
        .map_err(|e| render_error(&job.scene, e))?;
    set_render_stats(&mut stats, &rs);
    if job.describe_materials {
        stats.materials = renderer.materials().describe();
    }
    report.frames_in = 1;
    report.stages.decode_busy_ms = stats.load_ms + stats.render_cpu_ms + stats.render_pipelines_ms;
    report.scene = Some(stats);
    if let Some(dir) = &job.gbuffer {
        super::gbuffer::write_gbuffer(dir, &out, &ctx, &job.scene)?;
    }
    let Some(path) = &job.output else {
        report.wall_ms = ms(t_all.elapsed());
        return Ok(report);
    };
    let out_format = out_format.expect("output format checked");
    let (result_tex, result_format) = match effect.as_mut() {
        None => (None, Format::Rgba16f),
        Some(effect) => {
            let (target, format) = run_effect_on(
                job,
                engine,
                effect,
                (&renderer, &out),
                out_format,
                &mut report,
            )?;
            (Some(target), format)
        }
    };
    let (w, h) = result_tex
        .as_ref()
        .map(|t| (t.width(), t.height()))
        .unwrap_or((job.width, job.height));
    let result = result_tex.as_ref().unwrap_or(&out.scene);
    write_output(
        job,
        &ctx,
        (result, result_format, (w, h)),
        path,
        &mut report,
    )?;
    report.wall_ms = ms(t_all.elapsed());
    Ok(report)
}

/// The renderer's statistics of a still's one frame.
fn set_render_stats(stats: &mut SceneStats, rs: &RenderStats) {
    stats.render_cpu_ms = rs.cpu_ms;
    stats.render_cpu_split = rs.cpu_split.clone();
    stats.render_pipelines_ms = rs.pipeline_ms;
    stats.render_gpu_ms = rs.gpu_ms;
    stats.shadow_layers_rendered = rs.shadow_layers_rendered;
    stats.take_frame_counts(rs);
}

/// Runs the job's effects on the rendered frame `out` (the G-buffer as `AUX.*`, the
/// camera as standard values) into a new output texture of `out_format`'s plan: the
/// texture and its format; planning and pass times go to `report`.
fn run_effect_on(
    job: &SceneJob,
    engine: &mut Engine,
    effect: &mut Effect,
    (renderer, out): (&Renderer, &RenderOutput),
    out_format: Format,
    report: &mut RunReport,
) -> Result<(wgpu::Texture, Format), RunError> {
    let ctx = engine.ctx.clone();
    let job_aux = upload_job_aux(job, &ctx)?;
    let desc = job.effect_input(renderer, &job_aux);
    let t = Instant::now();
    let mut prepared = effect.prepare(engine, &desc, Some(out_format))?;
    report.steps.pipeline_ms = ms(t.elapsed());
    report.plans += 1;
    report.memory = MemoryReport::of(&prepared.plan);
    let o = prepared.plan.output;
    let target = create_output(&ctx, o.width, o.height, o.format);
    let t = Instant::now();
    let mut inputs = FrameInputs::still(&out.scene, &prepared.plan);
    inputs.aux = out.aux.iter().map(|(n, t)| (n.clone(), t.into())).collect();
    inputs
        .aux
        .extend(job_aux.iter().map(|(n, t, ..)| (n.clone(), t.into())));
    inputs.camera = Some(out.camera);
    report.passes = prepared.run(engine, &inputs, &target, job.timings)?;
    report.steps.passes_ms = ms(t.elapsed());
    Ok((target, o.format))
}

/// Reads `result` (`w`x`h`) back and writes it to `path` (the still's output), with
/// its timings and its line in `report`.
fn write_output(
    job: &SceneJob,
    ctx: &crate::gpu::context::GpuContext,
    (result, result_format, (w, h)): (&wgpu::Texture, Format, (u32, u32)),
    path: &std::path::Path,
    report: &mut RunReport,
) -> Result<(), RunError> {
    let t = Instant::now();
    let pixels = read_pixels(ctx, result, result_format)?;
    report.steps.readback_ms = ms(t.elapsed());
    let t = Instant::now();
    io::save_image(
        path,
        w,
        h,
        &pixels,
        &SaveOptions {
            bit_depth: job.bit_depth,
            assume_linear: false,
        },
    )?;
    let encode_ms = ms(t.elapsed());
    report.stages.encode_busy_ms = encode_ms;
    report.stages.gpu_busy_ms =
        report.steps.pipeline_ms + report.steps.passes_ms + report.steps.readback_ms;
    report.done.push(FrameDone {
        index: 0,
        input: job.scene.clone(),
        output: path.display().to_string(),
        width: w,
        height: h,
        // The scene's "input": loading and rendering it; its GPU part: the effects.
        decode_ms: Some(report.stages.decode_busy_ms),
        gpu_ms: Some(report.stages.gpu_busy_ms),
        encode_ms,
    });
    Ok(())
}
