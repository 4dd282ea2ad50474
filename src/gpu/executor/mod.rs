//! The executor: prepares a [`Plan`](crate::graph::plan::Plan) for a device
//! (shaders, reflection, pipelines, bind groups, static uniforms) and records it
//! frame after frame, interpreting the plan's `Alloc / Run / Free` steps as data.
//!
//! - [`Engine`]: device-level caches (pipelines, samplers, the texture pool) shared
//!   by every effect prepared on one device.
//! - [`Prepared`] (`record.rs`): one effect planned for one input; a frame is
//!   recorded into one command encoder ([`Prepared::record`], the caller's) or
//!   recorded and submitted in one submission ([`Prepared::run`]).
//! - `prepare.rs`: checks the plan against the device and builds everything that
//!   does not change from frame to frame.
//! - `encode.rs`: one pass: its views, its cached bind group, its render pass.
//! - `execution.rs`, `compute.rs`: [`Execution`], and passes run as compute
//!   dispatches (the fragment shader wrapped by [`crate::shader::compute`]).
//! - `prewarm.rs`: a plan's pipelines built side by side (one thread per core)
//!   before the passes are prepared in order.
//! - `pool.rs`: transient textures by descriptor, reused across frames.
//! - `params.rs`: [`Prepared::set_param`], parameters changed between frames.
//! - `caller.rs`: the caller's images of a frame, in the view formats the plan
//!   needs, and the output's format check.
//! - `bgra.rs`: outputs in the BGRA twin of an 8-bit output format (a window
//!   surface's), with a pipeline of their own for the passes that write them.
//! - `inspect.rs`: for tools: a copy of one pass's output ([`Prepared::inspect`])
//!   and per-pass GPU times of frames in the caller's encoder
//!   ([`Prepared::set_gpu_timings`]), neither changing the plan.

mod bgra;
mod caller;
mod compute;
mod encode;
mod execution;
mod inspect;
mod mips;
mod params;
mod pool;
mod prewarm;

/// The code of docs/library.md, compiled as doc-tests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/library.md")]
pub struct LibraryDoc;
mod prepare;
mod record;
mod stand_in;

pub use super::formats::wgpu_format;
pub use bgra::bgra_twin;
pub use execution::{default_execution, set_default_execution, Execution};
pub use params::{param_matches, ParamError, ParamInfo};
pub use pool::PoolStats;
pub use record::{Prepared, PreparedStats};

use super::bindings::{sampler_entry, texture_entry, uniform_entry};
use super::context::{GpuContext, GpuError};
use super::fullscreen::fullscreen_pipeline;
use crate::graph::plan::{Plan, Resource, View};
use crate::script::types::{Filter, Format, Sampling, Wrap};
use crate::script::Diagnostics;
use crate::shader::Reflection;
use pool::{Ids, TexturePool};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Errors of preparing or running an effect.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExecError {
    /// The script or a shader was rejected: render the diagnostics with the sources.
    #[error("{} error(s) in the effect or its shaders", .0.error_count())]
    Rejected(Diagnostics),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The frame's inputs or output do not fit the plan (missing input frame,
    /// wrong output format, a view where a texture is needed).
    #[error("{0}")]
    Input(String),
}

/// The format a texture of `f` is viewed in for `view` (`None`: its own).
pub(crate) fn view_format(f: Format, view: View) -> Option<wgpu::TextureFormat> {
    match (f, view) {
        (Format::Rgba8, View::SrgbDecode) => Some(wgpu::TextureFormat::Rgba8UnormSrgb),
        (Format::Rgba8Srgb, View::Raw) => Some(wgpu::TextureFormat::Rgba8Unorm),
        _ => None,
    }
}

/// Per-pass timing of one run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PassTiming {
    pub path: String,
    pub width: u32,
    pub height: u32,
    pub format: String,
    /// The path the pass ran on: a fragment pass or a compute dispatch.
    pub execution: Execution,
    /// GPU time from timestamp queries, when the adapter has them.
    pub gpu_ms: Option<f64>,
    /// CPU time to record the pass into the frame's command encoder.
    pub cpu_ms: f64,
    /// Frames these times are the medians of (1: one frame's own times).
    pub frames: u32,
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

/// An image the caller provides: a texture (the engine makes and caches the views
/// it needs, including an sRGB / raw view of 8-bit textures), or a view (used as
/// it is, so it must already be in the format the plan reads or writes).
#[derive(Debug, Clone, Copy)]
pub enum ImageRef<'a> {
    Texture(&'a wgpu::Texture),
    View(&'a wgpu::TextureView),
}

impl<'a> From<&'a wgpu::Texture> for ImageRef<'a> {
    fn from(t: &'a wgpu::Texture) -> Self {
        ImageRef::Texture(t)
    }
}

impl<'a> From<&'a wgpu::TextureView> for ImageRef<'a> {
    fn from(v: &'a wgpu::TextureView) -> Self {
        ImageRef::View(v)
    }
}

/// Images the caller provides for one frame.
#[derive(Debug, Clone, Default)]
pub struct FrameInputs<'a> {
    /// Input frames by offset (0 = current; others for `IN[-n]`/`IN[+n]`).
    pub frames: HashMap<i32, ImageRef<'a>>,
    pub aux: HashMap<String, ImageRef<'a>>,
    /// The camera, when the input comes from the renderer.
    pub camera: Option<CameraStd>,
    /// The sub-pixel jitter the current input frame was rendered with, in pixels:
    /// the offset of each pixel's sample position from the pixel centre, x right,
    /// y down (see [`crate::script::jitter`]). Shaders read it as the standard value
    /// `jitter`. `[0, 0]` (the default) for unjittered frames. A frame source that
    /// honours [`Prepared::jitter`] sets it to `pattern.offset(frame index)`.
    pub jitter: [f32; 2],
    /// The frame starts a new shot: the camera cut since the previous frame
    /// (the standard value `cut`, 1; effects with history drop it). `false`
    /// (the default) for every frame of a continuous sequence.
    pub cut: bool,
}

impl<'a> FrameInputs<'a> {
    /// A still image as a one-frame sequence: every `IN[n]` the plan reads is the
    /// image itself (history and future clamp to the only frame).
    pub fn still(input: impl Into<ImageRef<'a>>, plan: &Plan) -> Self {
        let input = input.into();
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

    /// Only the current frame (`IN`).
    pub fn single(input: impl Into<ImageRef<'a>>) -> Self {
        FrameInputs {
            frames: HashMap::from([(0, input.into())]),
            aux: HashMap::new(),
            camera: None,
            jitter: [0.0; 2],
            cut: false,
        }
    }

    /// Sets the frame's sub-pixel jitter (the standard value `jitter`).
    pub fn with_jitter(mut self, jitter: [f32; 2]) -> Self {
        self.jitter = jitter;
        self
    }

    /// Adds the auxiliary image `name` (`AUX.name`).
    pub fn with_aux(mut self, name: &str, image: impl Into<ImageRef<'a>>) -> Self {
        self.aux.insert(name.to_string(), image.into());
        self
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

/// Counters of an engine, for tests and reports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EngineStats {
    /// Render pipelines created (the cache's misses).
    pub pipelines_created: usize,
    /// Bind groups created, at prepare time and while recording frames.
    pub bind_groups_created: u64,
    /// Frames recorded on this engine.
    pub frames: u64,
    /// The texture pool.
    pub pool: PoolStats,
    /// Compute pipelines created (wrapped pass shaders).
    pub compute_pipelines_created: usize,
}

/// Device-level caches shared by every effect run on one device.
pub struct Engine {
    pub ctx: GpuContext,
    vs: wgpu::ShaderModule,
    pipelines: HashMap<PipelineKey, Arc<CachedPipeline>>,
    compute_pipelines: HashMap<compute::ComputeKey, Option<Arc<compute::CachedCompute>>>,
    /// The resolved execution (fragment or compute) of effects prepared next.
    execution: Execution,
    samplers: HashMap<(Sampling, bool), wgpu::Sampler>,
    pool: TexturePool,
    ids: Ids,
    /// Extra folders searched for `NAME.wgsl`.
    pub shader_dirs: Vec<PathBuf>,
    /// Number of pipelines created (for tests of the cache).
    pub pipelines_created: usize,
    compute_pipelines_created: usize,
    bind_groups_created: u64,
    frames: u64,
    /// The mip chains' pipelines, made on the first mipmapped texture.
    mips: Option<mips::MipChains>,
}

impl Engine {
    pub fn new(ctx: GpuContext) -> Self {
        let vs = ctx
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("fxgraph fullscreen vertex"),
                source: wgpu::ShaderSource::Wgsl(crate::shader::FULLSCREEN_VS.into()),
            });
        let mut engine = Engine {
            ctx,
            vs,
            pipelines: HashMap::new(),
            compute_pipelines: HashMap::new(),
            execution: Execution::Fragment,
            samplers: HashMap::new(),
            pool: TexturePool::new(),
            ids: Ids::default(),
            shader_dirs: Vec::new(),
            pipelines_created: 0,
            compute_pipelines_created: 0,
            bind_groups_created: 0,
            frames: 0,
            mips: None,
        };
        engine.set_execution(default_execution());
        engine
    }

    /// Run the passes of effects prepared from now on as `execution` says
    /// (`Auto` is resolved for this engine's adapter by [`Execution::resolve`]).
    /// Pooled textures made afterwards get the storage usage compute needs.
    pub fn set_execution(&mut self, execution: Execution) {
        self.execution = execution.resolve(&self.ctx.info);
        let formats = compute::storage_formats(self, self.execution == Execution::Compute);
        self.pool.set_storage_formats(formats);
        log::debug!("execution: {} ({execution} requested)", self.execution);
    }

    /// The execution of effects prepared next: `Fragment` or `Compute`.
    pub fn execution(&self) -> Execution {
        self.execution
    }

    /// The engine's counters: pipelines and bind groups created, frames recorded,
    /// textures the pool created, destroyed and holds.
    pub fn stats(&self) -> EngineStats {
        EngineStats {
            pipelines_created: self.pipelines_created,
            bind_groups_created: self.bind_groups_created,
            frames: self.frames,
            pool: self.pool.stats,
            compute_pipelines_created: self.compute_pipelines_created,
        }
    }

    /// Free pooled textures unused for more than `frames` frames are destroyed
    /// (default 8); 0 keeps only those the last frame used.
    pub fn set_pool_keep_frames(&mut self, frames: u64) {
        self.pool.keep_frames = frames;
    }

    pub(super) fn is_gl(&self) -> bool {
        self.ctx.info.backend == wgpu::Backend::Gl
    }

    fn format_filterable(&self, f: Format) -> bool {
        self.ctx.format_support(wgpu_format(f)).filter
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
        let built = build_render_pipeline(&self.ctx, &self.vs, key, refl, samplers, label)?;
        self.pipelines_created += 1;
        let arc = Arc::new(built);
        self.pipelines.insert(key.clone(), arc.clone());
        Ok(arc)
    }

    fn sampler(&mut self, s: Sampling, filtering: bool) -> wgpu::Sampler {
        self.samplers
            .entry((s, filtering))
            .or_insert_with(|| {
                let border = self
                    .ctx
                    .device
                    .features()
                    .contains(wgpu::Features::ADDRESS_MODE_CLAMP_TO_BORDER);
                if !border && (s.wrap_u == Wrap::Border || s.wrap_v == Wrap::Border) {
                    log::warn!(
                        "the adapter cannot sample with a border colour: `border` inputs \
                         clamp to the edge texel"
                    );
                }
                let mode = |w: Wrap| match w {
                    Wrap::Clamp => wgpu::AddressMode::ClampToEdge,
                    Wrap::Repeat => wgpu::AddressMode::Repeat,
                    Wrap::Mirror => wgpu::AddressMode::MirrorRepeat,
                    Wrap::Border if border => wgpu::AddressMode::ClampToBorder,
                    Wrap::Border => wgpu::AddressMode::ClampToEdge,
                };
                let border_color = (border
                    && (s.wrap_u == Wrap::Border || s.wrap_v == Wrap::Border))
                    .then_some(wgpu::SamplerBorderColor::TransparentBlack);
                let filter = if filtering && s.filter == Filter::Linear {
                    wgpu::FilterMode::Linear
                } else {
                    wgpu::FilterMode::Nearest
                };
                // A mipmapped input filters between levels as within one; any
                // other reads level 0 only, even of a texture that has more
                // levels for another reader.
                let (mipmap_filter, lod_max_clamp) = if s.mipmap {
                    let mip = match filter {
                        wgpu::FilterMode::Linear => wgpu::MipmapFilterMode::Linear,
                        wgpu::FilterMode::Nearest => wgpu::MipmapFilterMode::Nearest,
                    };
                    (mip, 32.0)
                } else {
                    (wgpu::MipmapFilterMode::Nearest, 0.0)
                };
                self.ctx.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some(&format!(
                        "sampler {} {}/{}{}",
                        s.filter.name(),
                        s.wrap_u.name(),
                        s.wrap_v.name(),
                        if s.mipmap { " mipmap" } else { "" }
                    )),
                    address_mode_u: mode(s.wrap_u),
                    address_mode_v: mode(s.wrap_v),
                    address_mode_w: wgpu::AddressMode::ClampToEdge,
                    mag_filter: filter,
                    min_filter: filter,
                    mipmap_filter,
                    lod_max_clamp,
                    border_color,
                    ..Default::default()
                })
            })
            .clone()
    }
}

/// The render pipeline of `key`: the fullscreen vertex shader `vs` and the pass's
/// fragment shader, with the bind group layout of its textures, samplers and
/// uniform. Needs only shared access, so that passes' pipelines can be built on
/// several threads (`prewarm.rs`).
fn build_render_pipeline(
    ctx: &GpuContext,
    vs: &wgpu::ShaderModule,
    key: &PipelineKey,
    refl: &Reflection,
    samplers: &[(u32, Sampling, bool)],
    label: &str,
) -> Result<CachedPipeline, GpuError> {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    let mut entries = Vec::new();
    for t in &refl.textures {
        let filterable = key
            .filterable
            .iter()
            .find(|(b, _)| *b == t.binding)
            .map(|(_, f)| *f)
            .unwrap_or(true);
        entries.push(texture_entry(
            t.binding,
            fragment,
            wgpu::TextureSampleType::Float { filterable },
            wgpu::TextureViewDimension::D2,
        ));
    }
    for (binding, _, filtering) in samplers {
        let ty = if *filtering {
            wgpu::SamplerBindingType::Filtering
        } else {
            wgpu::SamplerBindingType::NonFiltering
        };
        entries.push(sampler_entry(*binding, fragment, ty));
    }
    if let Some(u) = &refl.uniform {
        entries.push(uniform_entry(u.binding, fragment));
    }
    let cache = ctx.pipeline_cache.as_ref();
    ctx.scoped(label, |device| {
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
        let pipeline = fullscreen_pipeline(
            device,
            &format!("{label} pipeline"),
            Some(&pl),
            (vs, "vs_main"),
            (&module, &key.entry),
            key.target,
            cache,
        );
        CachedPipeline { pipeline, layout }
    })
}
