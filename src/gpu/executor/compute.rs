//! Passes run as compute dispatches (docs/architecture.md, "Execution paths").
//!
//! A pass prepared under [`Execution::Compute`](super::Execution) keeps its
//! render pipeline and gains a compute pipeline built from the same WGSL by
//! [`crate::shader::compute`]. At each frame the pass is dispatched as compute
//! when its target texture can be bound as a storage texture (pooled and ring
//! textures are created with that usage on such engines; a caller's output needs
//! `STORAGE_BINDING` too) and is drawn as before otherwise, so a caller that
//! passes a render-only output still gets a correct frame.

use super::encode::{bound_views, create_bind_group, target_view, BindKey, FrameTextures};
use super::record::{GpuPass, Source};
use super::stand_in::OutputTarget;
use super::{view_format, wgpu_format, Engine, ExecError, PipelineKey};
use crate::gpu::bindings::{sampler_entry, texture_entry, uniform_entry};
use crate::gpu::context::GpuError;
use crate::gpu::formats::wgsl_storage_format;
use crate::graph::plan::{PlannedPass, Resource};
use crate::script::types::{Format, Sampling};
use crate::script::Diagnostic;
use crate::shader::compute::{
    wrap_fragment_as_compute, StorageTarget, COMPUTE_ENTRY, WRAP_WORKGROUP,
};
use crate::shader::{ComputeNative, Reflection};
use std::sync::Arc;

/// Bind groups kept per pass, as for the fragment path.
const BIND_GROUPS_PER_PASS: usize = 8;

/// A compute pipeline with its bind group layout, shared like render pipelines.
pub(super) struct CachedCompute {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// What a compute pipeline is made from.
#[derive(Hash, PartialEq, Eq, Clone)]
pub(super) struct ComputeKey {
    /// The render pipeline's key, with `target` the storage format.
    pub(super) base: PipelineKey,
    encode_srgb: bool,
    /// The textures read with a mip chain (an implicit-level sample of one keeps
    /// the pass a fragment pass).
    pub(super) mipmapped: Vec<String>,
}

/// The compute path of one pass.
pub(super) struct ComputePath {
    pipeline: Arc<CachedCompute>,
    /// The storage texture's binding.
    binding: u32,
    /// The pass's target, viewed in `storage` (the storage view).
    target: Source,
    storage: wgpu::TextureFormat,
    size: (u32, u32),
    /// Invocations per workgroup in x and y: one invocation per output pixel.
    workgroup: (u32, u32),
    /// A compute-native pass writing the caller's output in another format
    /// than its own (an sRGB image, say): its values are converted into the
    /// output after the dispatch, sRGB-encoded when `Some(true)` (stand_in.rs).
    convert: Option<bool>,
    bind_groups: Vec<(Vec<BindKey>, wgpu::BindGroup)>,
}

/// The WGSL name of a storage texel format naga parsed.
fn naga_storage_name(f: naga::StorageFormat) -> &'static str {
    use naga::StorageFormat as S;
    match f {
        S::Rgba8Unorm => "rgba8unorm",
        S::Rgba16Float => "rgba16float",
        S::Rgba32Float => "rgba32float",
        S::Rgb10a2Unorm => "rgb10a2unorm",
        S::R8Unorm => "r8unorm",
        S::R16Float => "r16float",
        S::R32Float => "r32float",
        S::Rg16Float => "rg16float",
        S::Rg32Float => "rg32float",
        _ => "another format",
    }
}

/// The texture format of a four-channel float storage format naga parsed (the
/// formats a compute-native pass's values can be converted from).
fn wgpu_of_naga(f: naga::StorageFormat) -> Option<wgpu::TextureFormat> {
    match f {
        naga::StorageFormat::Rgba16Float => Some(wgpu::TextureFormat::Rgba16Float),
        naga::StorageFormat::Rgba32Float => Some(wgpu::TextureFormat::Rgba32Float),
        _ => None,
    }
}

/// The format a pass writing `f` stores to: `f`'s own, or for `rgba8-srgb` its
/// raw twin (the pool makes such textures in that format on compute engines).
fn storage_format(f: Format) -> wgpu::TextureFormat {
    wgpu_format(f).remove_srgb_suffix()
}

/// The formats whose pooled textures an engine under `compute` creates with
/// `STORAGE_BINDING`: those the device can store to.
pub(super) fn storage_formats(engine: &Engine, compute: bool) -> Vec<Format> {
    if !compute {
        return Vec::new();
    }
    Format::ALL
        .into_iter()
        .filter(|f| {
            let storage = storage_format(*f);
            wgsl_storage_format(storage).is_some() && engine.ctx.format_support(storage).storage
        })
        .collect()
}

impl Engine {
    /// The compute path of pass `p`, or `None` where it keeps the fragment path
    /// (fragment execution, a target format the device cannot store to, a target
    /// written through a raw view of an sRGB texture, or a shader only the
    /// fragment stage can run). `target` is where the pass writes, in its own
    /// format.
    pub(super) fn prepare_compute(
        &mut self,
        p: &PlannedPass,
        render_key: &PipelineKey,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        target: Source,
    ) -> Option<ComputePath> {
        let (key, st) = self.wrapped_key(p, render_key, refl)?;
        let binding = st.binding;
        let storage = key.base.target;
        let pipeline = self.compute_pipeline(&key, &st, refl, samplers, &p.path)?;
        Some(ComputePath {
            pipeline,
            binding,
            target,
            storage,
            size: (p.desc.width, p.desc.height),
            workgroup: WRAP_WORKGROUP,
            convert: None,
            bind_groups: Vec::new(),
        })
    }

    /// The key and storage target of the compute pipeline that wraps fragment
    /// pass `p` (with render pipeline key `render_key`), or `None` where the pass
    /// keeps the fragment path: a target format the device cannot store to.
    pub(super) fn wrapped_key(
        &self,
        p: &PlannedPass,
        render_key: &PipelineKey,
        refl: &Reflection,
    ) -> Option<(ComputeKey, StorageTarget)> {
        if !self.pool.stores(p.desc.format) {
            return None;
        }
        let storage = storage_format(p.desc.format);
        let format = wgsl_storage_format(storage)?;
        // Written through an sRGB view (or into an sRGB texture) on the fragment
        // path, where the hardware encodes: encode in the shader.
        let encode_srgb = view_format(p.desc.format, p.target_view)
            .unwrap_or(wgpu_format(p.desc.format))
            .is_srgb();
        let binding = 1 + refl
            .textures
            .iter()
            .map(|t| t.binding)
            .chain(refl.samplers.iter().map(|s| s.binding))
            .chain(refl.uniform.iter().map(|u| u.binding))
            .max()
            .unwrap_or(0);
        let key = ComputeKey {
            base: PipelineKey {
                target: storage,
                ..render_key.clone()
            },
            encode_srgb,
            mipmapped: p
                .inputs
                .iter()
                .filter(|i| i.sampling.mipmap)
                .map(|i| i.name.clone())
                .collect(),
        };
        let st = StorageTarget {
            format: format.to_string(),
            encode_srgb,
            binding,
        };
        Some((key, st))
    }

    /// The key and storage target of the compute pipeline of compute-native pass
    /// `p` where it stores in its own format (no conversion into the caller's
    /// output), as [`Engine::prepare_native`] makes them; `None` otherwise.
    pub(super) fn native_key(
        &self,
        p: &PlannedPass,
        render_key: &PipelineKey,
        native: &ComputeNative,
    ) -> Option<(ComputeKey, StorageTarget)> {
        let storage = storage_format(p.desc.format);
        let wanted = naga_storage_name(native.output.format);
        let mismatch =
            wgsl_storage_format(storage) != Some(wanted) || wgpu_format(p.desc.format).is_srgb();
        if mismatch || !self.ctx.format_support(storage).storage {
            return None;
        }
        let (key, st) = native_pipeline(storage, wanted, render_key, native);
        Some((key, st))
    }

    /// Whether the compute pipeline of `key` is cached (built, or known not to
    /// build).
    pub(super) fn has_compute_pipeline(&self, key: &ComputeKey) -> bool {
        self.compute_pipelines.contains_key(key)
    }

    /// Cache a compute pipeline built elsewhere (`prewarm.rs`).
    pub(super) fn insert_compute_pipeline(&mut self, key: ComputeKey, built: CachedCompute) {
        self.compute_pipelines_created += 1;
        self.compute_pipelines.insert(key, Some(Arc::new(built)));
    }

    /// Whether compute-native pass `p`, writing the caller's output as
    /// `rgba8-srgb` (an 8-bit image: no adapter stores to it), can have its
    /// values converted into the output: `Some(encode)` where the shader stores
    /// four float channels, the device can store those and the output's raw format, and
    /// `encode` (sRGB) is what the fragment path's target view would do.
    fn output_conversion(&self, p: &PlannedPass, native: &ComputeNative) -> Option<bool> {
        if !matches!(p.output, Resource::Output)
            || p.desc.format != Format::Rgba8Srgb
            || self.ctx.info.backend == wgpu::Backend::Gl
        {
            return None;
        }
        let stored = wgpu_of_naga(native.output.format)?;
        let raw = storage_format(p.desc.format);
        wgsl_storage_format(raw)?;
        let support = |f| self.ctx.format_support(f).storage;
        (support(stored) && support(raw)).then(|| {
            view_format(p.desc.format, p.target_view)
                .unwrap_or(wgpu_format(p.desc.format))
                .is_srgb()
        })
    }

    /// The compute path of a compute-native pass (its shader's own `@compute`
    /// entry point, docs/shaders.md): the output storage texture must be the
    /// format the pass writes, and one the device can store to.
    pub(super) fn prepare_native(
        &mut self,
        p: &PlannedPass,
        render_key: &PipelineKey,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        native: &ComputeNative,
        target: Source,
    ) -> Result<ComputePath, Diagnostic> {
        let storage = storage_format(p.desc.format);
        let declared = wgsl_storage_format(storage);
        let wanted = naga_storage_name(native.output.format);
        let mismatch = declared != Some(wanted) || wgpu_format(p.desc.format).is_srgb();
        // The caller's output in another format: stored in the shader's own
        // format, then converted (stand_in.rs).
        let convert = mismatch
            .then(|| self.output_conversion(p, native))
            .flatten();
        let storage = match convert {
            Some(_) => wgpu_of_naga(native.output.format).expect("checked by output_conversion"),
            None => storage,
        };
        if mismatch && convert.is_none() {
            return Err(Diagnostic::error(format!(
                "pass `{}` writes {}, but its shader's `{}` is a texture_storage_2d<{wanted}, write>",
                p.path, p.desc.format, native.output.name
            ))
            .note("set the pass's OUT.FORMAT to the storage format (rgba16f is rgba16float, r32f is r32float, ...); a compute pass cannot write rgba8-srgb"));
        }
        if !self.ctx.format_support(storage).storage {
            return Err(Diagnostic::error(format!(
                "pass `{}` is a compute pass writing {}, which this adapter ({}) cannot store to",
                p.path, p.desc.format, self.ctx.info.name
            )));
        }
        if convert.is_none() {
            self.pool.add_storage_format(p.desc.format);
        }
        let (key, st) = native_pipeline(storage, wanted, render_key, native);
        let [wx, wy, _] = native.workgroup;
        let pipeline = match self.compute_pipelines.get(&key) {
            Some(Some(p)) => p.clone(),
            _ => {
                let built = self
                    .build_compute(
                        &key,
                        (&key.base.wgsl.clone(), &key.base.entry.clone()),
                        &st,
                        refl,
                        samplers,
                        &p.path,
                    )
                    .map_err(|e| Diagnostic::error(format!("pass `{}`: {e}", p.path)))?;
                let built = Arc::new(built);
                self.compute_pipelines.insert(key, Some(built.clone()));
                built
            }
        };
        Ok(ComputePath {
            pipeline,
            binding: native.output.binding,
            target,
            storage,
            size: (p.desc.width, p.desc.height),
            workgroup: (wx.max(1), wy.max(1)),
            convert,
            bind_groups: Vec::new(),
        })
    }

    /// The cached compute pipeline of `key`; `None` (cached too) when the shader
    /// cannot run as compute or the pipeline fails to build.
    fn compute_pipeline(
        &mut self,
        key: &ComputeKey,
        st: &StorageTarget,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        label: &str,
    ) -> Option<Arc<CachedCompute>> {
        if let Some(p) = self.compute_pipelines.get(key) {
            return p.clone();
        }
        let built =
            match wrap_fragment_as_compute(&key.base.wgsl, &key.base.entry, st, &key.mipmapped) {
                Ok(wgsl) => {
                    match self.build_compute(key, (&wgsl, COMPUTE_ENTRY), st, refl, samplers, label)
                    {
                        Ok(p) => Some(Arc::new(p)),
                        Err(e) => {
                            log::warn!("pass `{label}` stays a fragment pass: {e}");
                            None
                        }
                    }
                }
                Err(why) => {
                    log::info!("pass `{label}` stays a fragment pass: {why}");
                    None
                }
            };
        self.compute_pipelines.insert(key.clone(), built.clone());
        built
    }

    /// Build the compute pipeline of `key` from `(wgsl, entry point)`.
    fn build_compute(
        &mut self,
        key: &ComputeKey,
        (wgsl, entry): (&str, &str),
        st: &StorageTarget,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        label: &str,
    ) -> Result<CachedCompute, GpuError> {
        let built =
            build_compute_pipeline(&self.ctx, key, (wgsl, entry), st, (refl, samplers), label)?;
        self.compute_pipelines_created += 1;
        Ok(built)
    }
}

/// The compute pipeline of `key` from `(wgsl, entry point)`. Needs only shared
/// access, so that passes' pipelines can be built on several threads
/// (`prewarm.rs`).
pub(super) fn build_compute_pipeline(
    ctx: &crate::gpu::context::GpuContext,
    key: &ComputeKey,
    (wgsl, entry): (&str, &str),
    st: &StorageTarget,
    (refl, samplers): (&Reflection, &[(u32, Sampling, bool)]),
    label: &str,
) -> Result<CachedCompute, GpuError> {
    let entries = compute_layout_entries(key, st, refl, samplers);
    let cache = ctx.pipeline_cache.as_ref();
    ctx.scoped(label, |device| {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&format!("{label} (compute)")),
            source: wgpu::ShaderSource::Wgsl(wgsl.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label} compute bind group layout")),
            entries: &entries,
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label} compute pipeline layout")),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&format!("{label} compute pipeline")),
            layout: Some(&pl),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache,
        });
        CachedCompute { pipeline, layout }
    })
}

/// The bind group layout of a wrapped pass: its textures, samplers and uniform
/// seen from the compute stage, and the storage target.
fn compute_layout_entries(
    key: &ComputeKey,
    st: &StorageTarget,
    refl: &Reflection,
    samplers: &[(u32, Sampling, bool)],
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let stage = wgpu::ShaderStages::COMPUTE;
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = refl
        .textures
        .iter()
        .map(|t| {
            let filterable = key
                .base
                .filterable
                .iter()
                .find(|(b, _)| *b == t.binding)
                .is_none_or(|(_, f)| *f);
            texture_entry(
                t.binding,
                stage,
                wgpu::TextureSampleType::Float { filterable },
                wgpu::TextureViewDimension::D2,
            )
        })
        .collect();
    for (binding, _, filtering) in samplers {
        let ty = if *filtering {
            wgpu::SamplerBindingType::Filtering
        } else {
            wgpu::SamplerBindingType::NonFiltering
        };
        entries.push(sampler_entry(*binding, stage, ty));
    }
    if let Some(u) = &refl.uniform {
        entries.push(uniform_entry(u.binding, stage));
    }
    entries.push(wgpu::BindGroupLayoutEntry {
        binding: st.binding,
        visibility: stage,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: key.base.target,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    });
    entries
}

/// The storage view of a pass's target this frame, when its texture allows one.
fn storage_target<'v>(
    path: &ComputePath,
    tex: FrameTextures<'v>,
) -> Option<(BindKey, &'v wgpu::TextureView)> {
    let (key, view) = target_view(&path.target, Some(path.storage), tex).ok()?;
    let texture = view.texture();
    (texture
        .usage()
        .contains(wgpu::TextureUsages::STORAGE_BINDING)
        && texture.format() == path.storage)
        .then_some((key, view))
}

impl GpuPass {
    /// Where this pass would write the caller's output through a stand-in
    /// (stand_in.rs): it has a compute path writing the output, and runs it
    /// under this execution (a pass that can be drawn is drawn under fragment
    /// execution).
    pub(super) fn output_target(&self, execution: super::Execution) -> Option<OutputTarget> {
        let path = self.compute.as_ref()?;
        let Source::Caller(caller_index) = path.target else {
            return None;
        };
        if self.pipeline.is_some() && execution != super::Execution::Compute {
            return None;
        }
        Some(OutputTarget {
            caller_index,
            storage: path.storage,
            convert: path.convert,
        })
    }

    /// Whether this frame can run the pass as compute: it has a compute path and
    /// its target can be bound for storage.
    pub(super) fn runs_as_compute(&self, tex: FrameTextures) -> bool {
        self.compute
            .as_ref()
            .is_some_and(|c| storage_target(c, tex).is_some())
    }
}

/// The compute bind group of `gp` for this frame's textures, made now where it
/// is not cached (`Prepared::prebind`, for a compute-native pass whose target
/// is a pooled texture that allows storage). Returns the number created.
pub(super) fn prebind_compute(gp: &mut GpuPass, device: &wgpu::Device, tex: FrameTextures) -> u64 {
    let Some(path) = gp.compute.as_ref() else {
        return 0;
    };
    let Some(target) = storage_target(path, tex) else {
        return 0;
    };
    let Ok(mut views) = bound_views(gp, tex) else {
        return 0;
    };
    views.push(target);
    compute_bind_group(gp, device, &views).1
}

/// The compute bind group of `gp` for `views` (its inputs, then the storage
/// target last): its index in the pass's cache and the number created (0 or 1).
fn compute_bind_group(
    gp: &mut GpuPass,
    device: &wgpu::Device,
    views: &[(BindKey, &wgpu::TextureView)],
) -> (usize, u64) {
    let path = gp.compute.as_ref().expect("a compute path");
    let key: Vec<BindKey> = views.iter().map(|(k, _)| k.clone()).collect();
    if let Some(i) = path.bind_groups.iter().position(|(k, _)| *k == key) {
        return (i, 0);
    }
    let (bound, target) = views.split_at(views.len() - 1);
    let bg = create_bind_group(
        device,
        &format!("{} compute bind group", gp.path),
        &path.pipeline.layout,
        gp,
        bound,
        Some((path.binding, target[0].1)),
    );
    let path = gp.compute.as_mut().expect("a compute path");
    if path.bind_groups.len() == BIND_GROUPS_PER_PASS {
        path.bind_groups.remove(0);
    }
    path.bind_groups.push((key, bg));
    (path.bind_groups.len() - 1, 1)
}

/// Record one pass as a compute dispatch over its target (one invocation per
/// pixel). Call only when [`GpuPass::runs_as_compute`] said so. Returns the
/// number of bind groups created.
pub(super) fn encode_compute_pass(
    gp: &mut GpuPass,
    device: &wgpu::Device,
    tex: FrameTextures,
    encoder: &mut wgpu::CommandEncoder,
    timestamps: Option<wgpu::ComputePassTimestampWrites>,
) -> Result<u64, ExecError> {
    let mut views = bound_views(gp, tex)?;
    let path = gp.compute.as_ref().expect("a compute path");
    let target = storage_target(path, tex)
        .ok_or_else(|| ExecError::Input(format!("pass `{}`: no storage view", gp.path)))?;
    views.push(target);
    let (bg, created) = compute_bind_group(gp, device, &views);
    let path = gp.compute.as_ref().expect("a compute path");
    let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(&gp.path),
        timestamp_writes: timestamps,
    });
    cp.set_pipeline(&path.pipeline.pipeline);
    cp.set_bind_group(0, &path.bind_groups[bg].1, &[]);
    let (wx, wy) = path.workgroup;
    cp.dispatch_workgroups(path.size.0.div_ceil(wx), path.size.1.div_ceil(wy), 1);
    Ok(created)
}

/// The key and storage target of compute-native pass `native`'s pipeline,
/// storing `storage` as the shader's `wanted` format (no sRGB encoding, no
/// mipmaps).
fn native_pipeline(
    storage: wgpu::TextureFormat,
    wanted: &str,
    render_key: &PipelineKey,
    native: &ComputeNative,
) -> (ComputeKey, StorageTarget) {
    let key = ComputeKey {
        base: PipelineKey {
            target: storage,
            ..render_key.clone()
        },
        encode_srgb: false,
        mipmapped: Vec::new(),
    };
    let st = StorageTarget {
        format: wanted.to_string(),
        encode_srgb: false,
        binding: native.output.binding,
    };
    (key, st)
}
