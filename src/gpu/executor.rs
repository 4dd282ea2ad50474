//! The executor: prepares a [`Plan`] for a device (shaders, reflection, pipelines)
//! and runs it frame after frame, interpreting the plan's `Alloc / Run / Free` steps.

use super::context::{GpuContext, GpuError, GpuTimer};
use crate::graph::plan::{Plan, Resource, ReusePolicy, Step, TextureDesc, View};
use crate::graph::Graph;
use crate::script::types::{Filter, Format, Sampling, Wrap};
use crate::script::{Diagnostic, Diagnostics, SourceMap};
use crate::shader::reflect::StdContext;
use crate::shader::{load_plan_shaders, Reflection, UniformLayout, FULLSCREEN_VS};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Errors of preparing or running an effect.
#[derive(Debug, thiserror::Error)]
pub enum ExecError {
    /// The script or a shader was rejected: render the diagnostics with the sources.
    #[error("{} error(s) in the effect or its shaders", .0.error_count())]
    Rejected(Diagnostics),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("{0}")]
    Input(String),
}

/// The wgpu format of a script format.
pub fn wgpu_format(f: Format) -> wgpu::TextureFormat {
    use wgpu::TextureFormat as T;
    match f {
        Format::Rgba8 => T::Rgba8Unorm,
        Format::Rgba8Srgb => T::Rgba8UnormSrgb,
        Format::Rgba16f => T::Rgba16Float,
        Format::Rgba32f => T::Rgba32Float,
        Format::Rgb10a2 => T::Rgb10a2Unorm,
        Format::R8 => T::R8Unorm,
        Format::R16f => T::R16Float,
        Format::R32f => T::R32Float,
        Format::Rg16f => T::Rg16Float,
        Format::Rg32f => T::Rg32Float,
    }
}

fn view_format(f: Format, view: View) -> Option<wgpu::TextureFormat> {
    match (f, view) {
        (Format::Rgba8, View::SrgbDecode) => Some(wgpu::TextureFormat::Rgba8UnormSrgb),
        (Format::Rgba8Srgb, View::Raw) => Some(wgpu::TextureFormat::Rgba8Unorm),
        _ => None,
    }
}

/// A render pipeline with its bind group layout, shared by passes with the same
/// shader text, target format and input filterability.
struct CachedPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

#[derive(Hash, PartialEq, Eq, Clone)]
struct PipelineKey {
    wgsl: Arc<str>,
    entry: String,
    target: wgpu::TextureFormat,
    /// Per texture binding: can it be filtered.
    filterable: Vec<(u32, bool)>,
}

/// Device-level caches shared by every effect run on one device.
pub struct Engine {
    pub ctx: GpuContext,
    vs: wgpu::ShaderModule,
    pipelines: HashMap<PipelineKey, Arc<CachedPipeline>>,
    samplers: HashMap<(Sampling, bool), wgpu::Sampler>,
    /// Extra folders searched for `NAME.wgsl`.
    pub shader_dirs: Vec<PathBuf>,
    /// Number of pipelines created (for tests of the cache).
    pub pipelines_created: usize,
}

/// What one prepared pass binds.
struct GpuPass {
    path: String,
    pipeline: Arc<CachedPipeline>,
    /// (binding, input index into PlannedPass::inputs)
    textures: Vec<(u32, usize)>,
    /// (binding, sampling, filtering)
    samplers: Vec<(u32, Sampling, bool)>,
    uniform: Option<(u32, UniformLayout, wgpu::Buffer)>,
}

/// A plan prepared for a device, with its textures; run it with [`Prepared::run`].
pub struct Prepared {
    pub plan: Plan,
    passes: Vec<GpuPass>,
    slots: Vec<Option<wgpu::Texture>>,
    rings: Vec<Vec<wgpu::Texture>>,
    ring_head: Vec<usize>,
    pub policy: ReusePolicy,
    pub frame: u64,
    /// Index of the output produced for the current input frame (see `Stream::rate`).
    pub subframe: u32,
    pub fps: f64,
    timer: Option<GpuTimer>,
    /// Time spent creating shader modules and pipelines.
    pub pipeline_build: std::time::Duration,
}

/// Per-pass timing of one run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PassTiming {
    pub path: String,
    pub width: u32,
    pub height: u32,
    pub format: String,
    /// GPU time from timestamp queries, when the adapter has them.
    pub gpu_ms: Option<f64>,
    /// CPU time to record and submit the pass.
    pub cpu_ms: f64,
}

/// The camera of a rendered input, for the standard values `near`, `far`, `proj`
/// and `inv_proj` (column-major matrices, as WGSL reads them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraStd {
    pub near: f32,
    pub far: f32,
    pub proj: [f32; 16],
    pub inv_proj: [f32; 16],
}

/// Textures the caller provides for one frame.
pub struct FrameInputs<'a> {
    /// Input frames by offset (0 = current; others for `IN[-n]`/`IN[+n]`).
    pub frames: HashMap<i32, &'a wgpu::Texture>,
    pub aux: HashMap<String, &'a wgpu::Texture>,
    /// The camera, when the input comes from the renderer.
    pub camera: Option<CameraStd>,
}

impl<'a> FrameInputs<'a> {
    /// A still image as a one-frame sequence: every `IN[n]` the plan reads is the
    /// image itself (history and future clamp to the only frame).
    pub fn still(input: &'a wgpu::Texture, plan: &Plan) -> Self {
        let mut f = Self::single(input);
        for p in &plan.passes {
            for i in &p.inputs {
                if let Resource::Input { frame } = i.resource {
                    f.frames.insert(frame, input);
                }
            }
        }
        f
    }

    pub fn single(input: &'a wgpu::Texture) -> Self {
        FrameInputs {
            frames: HashMap::from([(0, input)]),
            aux: HashMap::new(),
            camera: None,
        }
    }
}

impl Engine {
    pub fn new(ctx: GpuContext) -> Self {
        let vs = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("fxgraph fullscreen vertex"),
                source: wgpu::ShaderSource::Wgsl(FULLSCREEN_VS.into()),
            });
        Engine {
            ctx,
            vs,
            pipelines: HashMap::new(),
            samplers: HashMap::new(),
            shader_dirs: Vec::new(),
            pipelines_created: 0,
        }
    }

    fn format_filterable(&self, f: Format) -> bool {
        self.ctx.format_support(wgpu_format(f)).filter
    }

    /// Check the plan against the device, load and reflect every shader, and build
    /// the pipelines. All problems are returned together as diagnostics.
    pub fn prepare(
        &mut self,
        graph: &Graph,
        plan: Plan,
        sources: &mut SourceMap,
    ) -> Result<Prepared, ExecError> {
        let start = Instant::now();
        let mut diags = Diagnostics::default();
        let max = self.ctx.device.limits().max_texture_dimension_2d;
        let adapter = self.ctx.info.name.clone();
        let (shaders, shader_diags) = load_plan_shaders(graph, &plan, sources, &self.shader_dirs);
        diags.extend(shader_diags);
        let mut passes = Vec::new();
        for (pi, p) in plan.passes.iter().enumerate() {
            let span = p.node.map(|n| graph.pass(n).name_span);
            let at = |d: Diagnostic| match span {
                Some(s) => d.at(s, ""),
                None => d,
            };
            if p.desc.width > max || p.desc.height > max {
                diags.push(at(Diagnostic::error(format!(
                    "pass `{}` is {}x{} px; this adapter ({adapter}) allows at most {max} px on a side",
                    p.path, p.desc.width, p.desc.height
                ))));
                continue;
            }
            let target =
                view_format(p.desc.format, p.target_view).unwrap_or(wgpu_format(p.desc.format));
            if p.target_view != View::Natural && self.ctx.info.backend == wgpu::Backend::Gl {
                diags.push(at(Diagnostic::error(format!(
                    "pass `{}` writes sRGB-encoded values to an sRGB target, which needs a texture view the GL backend cannot make",
                    p.path
                ))
                .note("use the Vulkan backend (lavapipe) or write linear values")));
                continue;
            }
            if !self.ctx.format_support(target).render {
                diags.push(at(Diagnostic::error(format!(
                    "pass `{}` renders to {}, which this adapter ({adapter}) cannot render to",
                    p.path, p.desc.format
                ))
                .note("choose another OUT.FORMAT, e.g. rgba16f")));
                continue;
            }
            let Some(loaded) = shaders[pi].clone() else {
                continue;
            };
            let (wgsl, refl, layout) = (loaded.wgsl, loaded.reflection, loaded.layout);
            // Textures and samplers by name; filterability from the bound formats.
            let mut textures = Vec::new();
            let mut filterable = Vec::new();
            let mut ok = true;
            for t in &refl.textures {
                let Some(ii) = p.inputs.iter().position(|i| i.name == t.name) else {
                    ok = false;
                    continue;
                };
                let inp = &p.inputs[ii];
                let f = self.format_filterable(inp.desc.format);
                if !f
                    && inp.sampling.filter == Filter::Linear
                    && refl
                        .samplers
                        .iter()
                        .any(|s| s.name == format!("{}_sampler", t.name))
                {
                    let span = p
                        .node
                        .and_then(|n| graph.pass(n).inputs.get(ii).map(|i| i.span));
                    let d = Diagnostic::error(format!(
                        "input `{}` of pass `{}` is {}, which this adapter ({adapter}) cannot filter",
                        inp.name, p.path, inp.desc.format
                    ))
                    .note(format!("set `{}.FILTER = nearest`, or use a 16-bit float format", inp.name));
                    diags.push(match span {
                        Some(s) => d.at(s, "linear filtering requested"),
                        None => d,
                    });
                    ok = false;
                }
                if inp.view != View::Natural && self.ctx.info.backend == wgpu::Backend::Gl {
                    diags.push(at(Diagnostic::error(format!(
                        "pass `{}` needs to view `{}` in another colour space, which the GL backend cannot do",
                        p.path, inp.name
                    ))));
                    ok = false;
                }
                textures.push((t.binding, ii));
                filterable.push((t.binding, f));
            }
            let mut samplers = Vec::new();
            for s in &refl.samplers {
                let (sampling, filtering) = match s
                    .name
                    .strip_suffix("_sampler")
                    .and_then(|n| p.inputs.iter().find(|i| i.name == n))
                {
                    Some(inp) => (
                        inp.sampling,
                        inp.sampling.filter == Filter::Linear
                            && self.format_filterable(inp.desc.format),
                    ),
                    None => {
                        let all = p
                            .inputs
                            .iter()
                            .all(|i| self.format_filterable(i.desc.format));
                        (Sampling::default(), all)
                    }
                };
                samplers.push((s.binding, sampling, filtering));
            }
            if !ok {
                continue;
            }
            let key = PipelineKey {
                wgsl: wgsl.clone(),
                entry: refl.entry_point.clone(),
                target,
                filterable: filterable.clone(),
            };
            let pipeline = match self.pipeline(&key, &refl, &samplers, &p.path) {
                Ok(pl) => pl,
                Err(e) => {
                    diags.push(at(Diagnostic::error(format!("pass `{}`: {e}", p.path))));
                    continue;
                }
            };
            let uniform = refl.uniform.as_ref().map(|u| {
                let buffer = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("{} uniforms", p.path)),
                    size: u64::from(layout.size.max(16)).next_multiple_of(16),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                (u.binding, layout.clone(), buffer)
            });
            passes.push(GpuPass {
                path: p.path.clone(),
                pipeline,
                textures,
                samplers,
                uniform,
            });
        }
        if diags.has_errors() {
            diags.sort();
            return Err(ExecError::Rejected(diags));
        }
        let rings = plan
            .rings
            .iter()
            .map(|r| {
                (0..=r.depth)
                    .map(|i| self.create_texture(&format!("{} history {i}", r.pass), r.desc))
                    .collect::<Vec<_>>()
            })
            .collect::<Vec<_>>();
        let timer = GpuTimer::new(&self.ctx, plan.passes.len() as u32);
        Ok(Prepared {
            ring_head: vec![0; rings.len()],
            rings,
            slots: vec![None; plan.slots.len()],
            plan,
            passes,
            policy: ReusePolicy::MinPeak,
            frame: 0,
            subframe: 0,
            fps: 25.0,
            timer,
            pipeline_build: start.elapsed(),
        })
    }

    fn pipeline(
        &mut self,
        key: &PipelineKey,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        label: &str,
    ) -> Result<Arc<CachedPipeline>, GpuError> {
        if let Some(p) = self.pipelines.get(key) {
            return Ok(p.clone());
        }
        let mut entries = Vec::new();
        for t in &refl.textures {
            let filterable = key
                .filterable
                .iter()
                .find(|(b, _)| *b == t.binding)
                .map(|(_, f)| *f)
                .unwrap_or(true);
            entries.push(wgpu::BindGroupLayoutEntry {
                binding: t.binding,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            });
        }
        for (binding, _, filtering) in samplers {
            entries.push(wgpu::BindGroupLayoutEntry {
                binding: *binding,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(if *filtering {
                    wgpu::SamplerBindingType::Filtering
                } else {
                    wgpu::SamplerBindingType::NonFiltering
                }),
                count: None,
            });
        }
        if let Some(u) = &refl.uniform {
            entries.push(wgpu::BindGroupLayoutEntry {
                binding: u.binding,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            });
        }
        let vs = self.vs.clone();
        let built = self.ctx.scoped(label, |device| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(std::borrow::Cow::Owned(key.wgsl.to_string())),
            });
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(&format!("{label} bind group layout")),
                entries: &entries,
            });
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&format!("{label} pipeline layout")),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&format!("{label} pipeline")),
                layout: Some(&pl),
                vertex: wgpu::VertexState {
                    module: &vs,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(&key.entry),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: key.target,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
            CachedPipeline { pipeline, layout }
        })?;
        self.pipelines_created += 1;
        let arc = Arc::new(built);
        self.pipelines.insert(key.clone(), arc.clone());
        Ok(arc)
    }

    fn sampler(&mut self, s: Sampling, filtering: bool) -> wgpu::Sampler {
        self.samplers
            .entry((s, filtering))
            .or_insert_with(|| {
                let mode = |w: Wrap| match w {
                    Wrap::Clamp => wgpu::AddressMode::ClampToEdge,
                    Wrap::Repeat => wgpu::AddressMode::Repeat,
                    Wrap::Mirror => wgpu::AddressMode::MirrorRepeat,
                };
                let filter = if filtering && s.filter == Filter::Linear {
                    wgpu::FilterMode::Linear
                } else {
                    wgpu::FilterMode::Nearest
                };
                self.ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some(&format!(
                        "sampler {} {}/{}",
                        s.filter.name(),
                        s.wrap_u.name(),
                        s.wrap_v.name()
                    )),
                    address_mode_u: mode(s.wrap_u),
                    address_mode_v: mode(s.wrap_v),
                    address_mode_w: wgpu::AddressMode::ClampToEdge,
                    mag_filter: filter,
                    min_filter: filter,
                    ..Default::default()
                })
            })
            .clone()
    }

    /// A render target / sampled texture for a transient value or ring.
    pub fn create_texture(&self, label: &str, d: TextureDesc) -> wgpu::Texture {
        let format = wgpu_format(d.format);
        let view_formats: &[wgpu::TextureFormat] = if self.ctx.info.backend == wgpu::Backend::Gl {
            &[]
        } else {
            match d.format {
                Format::Rgba8 => &[wgpu::TextureFormat::Rgba8UnormSrgb],
                Format::Rgba8Srgb => &[wgpu::TextureFormat::Rgba8Unorm],
                _ => &[],
            }
        };
        self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: d.width,
                height: d.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats,
        })
    }
}

impl Prepared {
    /// Run one frame: every step of the plan, writing the result into `output`
    /// (a texture of `plan.output`'s size and format with RENDER_ATTACHMENT usage).
    /// Returns per-pass timings.
    pub fn run(
        &mut self,
        engine: &mut Engine,
        inputs: &FrameInputs,
        output: &wgpu::Texture,
        want_timings: bool,
    ) -> Result<Vec<PassTiming>, ExecError> {
        let out_fmt = wgpu_format(self.plan.output.format);
        if output.format() != out_fmt
            && output.format().remove_srgb_suffix() != out_fmt.remove_srgb_suffix()
        {
            return Err(ExecError::Input(format!(
                "output texture is {:?}, the plan renders {:?}",
                output.format(),
                out_fmt
            )));
        }
        for (frame, _) in self
            .plan
            .passes
            .iter()
            .flat_map(|p| p.inputs.iter())
            .filter_map(|i| match i.resource {
                Resource::Input { frame } => Some((frame, ())),
                _ => None,
            })
        {
            if !inputs.frames.contains_key(&frame) {
                return Err(ExecError::Input(format!(
                    "input frame {frame:+} not provided"
                )));
            }
        }
        let ctx = engine.ctx.clone();
        let camera = inputs.camera.unwrap_or(CameraStd {
            near: 0.1,
            far: 100.0,
            proj: IDENTITY,
            inv_proj: IDENTITY,
        });
        let std_base = StdContext {
            frame: self.frame,
            time: self.frame as f64 / self.fps,
            subframe: self.subframe,
            near: camera.near,
            far: camera.far,
            proj: camera.proj,
            inv_proj: camera.inv_proj,
            ..Default::default()
        };
        let timer = if want_timings {
            self.timer.take()
        } else {
            None
        };
        let mut timings = Vec::new();
        let mut to_release: Vec<wgpu::Texture> = Vec::new();
        let mut pass_i = 0usize;
        let result: Result<(), ExecError> = (|| {
            for si in 0..self.plan.steps.len() {
                match self.plan.steps[si] {
                    Step::Alloc { slot, .. } => {
                        if self.slots[slot].is_none() {
                            let d = self.plan.slots[slot];
                            self.slots[slot] = Some(engine.create_texture(
                                &format!("transient t{slot} {}x{} {}", d.width, d.height, d.format),
                                d,
                            ));
                        }
                    }
                    Step::Free { slot, release, .. } => {
                        if release && self.policy == ReusePolicy::MinPeak {
                            if let Some(t) = self.slots[slot].take() {
                                to_release.push(t);
                            }
                        }
                    }
                    Step::Run { pass } => {
                        let t0 = Instant::now();
                        self.encode_pass(
                            engine,
                            &ctx,
                            pass,
                            inputs,
                            output,
                            &std_base,
                            timer.as_ref().map(|t| (t, pass_i as u32)),
                        )?;
                        pass_i += 1;
                        // Textures released by the steps after the previous pass:
                        // its work is submitted, so they go back now.
                        for t in to_release.drain(..) {
                            t.destroy();
                        }
                        let p = &self.plan.passes[pass];
                        timings.push(PassTiming {
                            path: p.path.clone(),
                            width: p.desc.width,
                            height: p.desc.height,
                            format: p.desc.format.name().to_string(),
                            gpu_ms: None,
                            cpu_ms: t0.elapsed().as_secs_f64() * 1e3,
                        });
                    }
                }
            }
            Ok(())
        })();
        if let Some(t) = &timer {
            if result.is_ok() {
                let mut enc = ctx
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("fxgraph timestamps resolve"),
                    });
                t.resolve(&mut enc, pass_i as u32);
                ctx.queue.submit([enc.finish()]);
                if let Ok(ms) = t.read_ms(&ctx, pass_i as u32) {
                    for (tm, v) in timings.iter_mut().zip(ms) {
                        tm.gpu_ms = Some(v);
                    }
                }
            }
        }
        if timer.is_some() {
            self.timer = timer;
        }
        result?;
        let errors = ctx.take_uncaptured_errors();
        if let Some(e) = errors.first() {
            return Err(ExecError::Gpu(GpuError::Validation {
                what: "frame".into(),
                message: e.clone(),
            }));
        }
        // Feedback rings: this frame's output becomes "one frame ago".
        for (r, ring) in self.rings.iter().enumerate() {
            let n = ring.len();
            self.ring_head[r] = (self.ring_head[r] + n - 1) % n;
        }
        self.frame += 1;
        Ok(timings)
    }

    fn texture_for<'t>(
        &'t self,
        r: &Resource,
        inputs: &'t FrameInputs,
        output: &'t wgpu::Texture,
    ) -> Result<&'t wgpu::Texture, ExecError> {
        Ok(match r {
            Resource::Input { frame } => {
                inputs.frames.get(frame).copied().ok_or_else(|| {
                    ExecError::Input(format!("input frame {frame:+} not provided"))
                })?
            }
            Resource::Aux(name) => inputs.aux.get(name).copied().ok_or_else(|| {
                ExecError::Input(format!("auxiliary input `{name}` not provided"))
            })?,
            Resource::Value(v) => self.slots[self.plan.values[*v].slot]
                .as_ref()
                .expect("allocated before use"),
            Resource::Persistent { ring, back } => {
                let n = self.rings[*ring].len();
                &self.rings[*ring][(self.ring_head[*ring] + *back as usize) % n]
            }
            Resource::Output => output,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn encode_pass(
        &self,
        engine: &mut Engine,
        ctx: &GpuContext,
        index: usize,
        inputs: &FrameInputs,
        output: &wgpu::Texture,
        std_base: &StdContext,
        timer: Option<(&GpuTimer, u32)>,
    ) -> Result<(), ExecError> {
        let gp = &self.passes[index];
        let p = &self.plan.passes[index];
        let target = self.texture_for(&p.output, inputs, output)?;
        let samplers: Vec<(u32, wgpu::Sampler)> = gp
            .samplers
            .iter()
            .map(|(b, s, f)| (*b, engine.sampler(*s, *f)))
            .collect();
        ctx.scoped(&gp.path, |device| -> Result<(), ExecError> {
            let mut views = Vec::new();
            for (binding, ii) in &gp.textures {
                let inp = &p.inputs[*ii];
                let tex = self.texture_for(&inp.resource, inputs, output)?;
                let view = tex.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("{} {}", gp.path, inp.name)),
                    format: view_format(inp.desc.format, inp.view),
                    ..Default::default()
                });
                views.push((*binding, view));
            }
            let std = StdContext {
                out_size: (p.desc.width, p.desc.height),
                input_sizes: p
                    .inputs
                    .iter()
                    .map(|i| (i.desc.width, i.desc.height))
                    .collect(),
                ..std_base.clone()
            };
            let mut entries: Vec<wgpu::BindGroupEntry> = Vec::new();
            for (b, v) in &views {
                entries.push(wgpu::BindGroupEntry {
                    binding: *b,
                    resource: wgpu::BindingResource::TextureView(v),
                });
            }
            for (b, s) in &samplers {
                entries.push(wgpu::BindGroupEntry {
                    binding: *b,
                    resource: wgpu::BindingResource::Sampler(s),
                });
            }
            if let Some((b, layout, buffer)) = &gp.uniform {
                ctx.queue.write_buffer(buffer, 0, &layout.write(&std));
                entries.push(wgpu::BindGroupEntry {
                    binding: *b,
                    resource: buffer.as_entire_binding(),
                });
            }
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{} bind group", gp.path)),
                layout: &gp.pipeline.layout,
                entries: &entries,
            });
            let target_view = target.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{} target", gp.path)),
                format: Some(
                    view_format(p.desc.format, p.target_view).unwrap_or(wgpu_format(p.desc.format)),
                ),
                ..Default::default()
            });
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(&gp.path),
            });
            {
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(&gp.path),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &target_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            // SAFETY: the fullscreen triangle writes every pixel of the target.
                            load: wgpu::LoadOp::DontCare(unsafe {
                                wgpu::LoadOpDontCare::enabled()
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: timer.and_then(|(t, i)| t.pass_writes(i)),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(&gp.pipeline.pipeline);
                rp.set_bind_group(0, &bind_group, &[]);
                rp.draw(0..3, 0..1);
            }
            ctx.queue.submit([encoder.finish()]);
            Ok(())
        })??;
        Ok(())
    }
}

const IDENTITY: [f32; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];
