//! Preparing a plan for a device: check it against the adapter, load and reflect
//! the shaders, build (or reuse) the pipelines, and make everything a frame does
//! not change: samplers, uniform buffers with their static values written once,
//! feedback rings with their views, and the bind groups of passes that bind only
//! the engine's own textures.

use super::bgra::TwinPipeline;
use super::pool::PooledTexture;
use super::record::{CallerRef, GpuPass, PassUniform, Prepared, PreparedStats, Source, NO_CAMERA};
use super::{view_format, wgpu_format, Engine, ExecError, PipelineKey};
use crate::gpu::context::GpuTimer;
use crate::graph::plan::{Plan, PlannedPass, Resource, View};
use crate::graph::Graph;
use crate::script::types::{Filter, Sampling};
use crate::script::{Diagnostic, Diagnostics, SourceMap};
use crate::shader::reflect::{StdContext, UniformBlock};
use crate::shader::Reflection;
use crate::shader::UniformLayout;
use crate::shader::{load_plan_shaders_with, LoadedShader, ShaderCache};
use std::sync::Arc;
use std::time::Instant;

/// A pass's render pipeline, compute path and the render pipeline's key.
type PassPipelines = (
    Option<Arc<super::CachedPipeline>>,
    Option<super::compute::ComputePath>,
    PipelineKey,
);

/// The textures (binding, input index), their filterability (binding, filterable)
/// and the samplers (binding, sampling, filtering) of a pass's shader.
pub(super) struct PassBindings {
    textures: Vec<(u32, usize)>,
    pub(super) filterable: Vec<(u32, bool)>,
    pub(super) samplers: Vec<(u32, Sampling, bool)>,
}

/// The source of a resource; caller images are added to `caller` once each.
fn source_of(
    r: &Resource,
    format: Option<wgpu::TextureFormat>,
    plan: &Plan,
    caller: &mut Vec<CallerRef>,
) -> Source {
    match r {
        Resource::Value(v) => Source::Slot(plan.values[*v].slot),
        Resource::Persistent { ring, back } => Source::Ring {
            ring: *ring,
            back: *back,
        },
        Resource::Input { .. } | Resource::Aux(_) | Resource::Output => {
            let c = CallerRef {
                resource: r.clone(),
                format,
            };
            let i = match caller.iter().position(|x| *x == c) {
                Some(i) => i,
                None => {
                    caller.push(c);
                    caller.len() - 1
                }
            };
            Source::Caller(i)
        }
    }
}

impl Engine {
    /// The pipelines of pass `p`: a fragment pass has its render pipeline (and a
    /// compute one under compute execution, made by the caller); a compute-native
    /// pass its compute path. A compute-native shader with a `@fragment` entry
    /// point too (docs/shaders.md, "Compute passes") also gets the render
    /// pipeline of that entry where the compute path cannot be made on this
    /// adapter or for this format, or where the pass writes the caller's output
    /// (which may be an sRGB or BGRA texture); the frame then draws it where the
    /// target cannot be stored to. Under fragment execution a pass whose
    /// invocations share output texels (a reduction, a tile maximum, a block
    /// matcher's lanes: a third workgroup size above 1) is drawn: on lavapipe
    /// such dispatches cost more than the fragment pass over the same footprint. Returns the render
    /// pipeline's key too.
    fn pass_pipelines(
        &mut self,
        p: &PlannedPass,
        key: PipelineKey,
        refl: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        plan: &Plan,
        caller: &mut Vec<CallerRef>,
    ) -> Result<PassPipelines, Diagnostic> {
        let render = |engine: &mut Engine, key: &PipelineKey| {
            engine
                .pipeline(key, refl, samplers, &p.path)
                .map_err(|e| Diagnostic::error(format!("pass `{}`: {e}", p.path)))
        };
        let Some(native) = &refl.compute else {
            return Ok((Some(render(self, &key)?), None, key));
        };
        let Some(entry) = &native.fragment else {
            let target = source_of(&p.output, None, plan, caller);
            let path = self.prepare_native(p, &key, refl, samplers, native, target)?;
            return Ok((None, Some(path), key));
        };
        let fragment_key = PipelineKey {
            entry: entry.clone(),
            ..key.clone()
        };
        if self.execution == super::Execution::Fragment && native.drawn_under_fragment_execution() {
            return Ok((Some(render(self, &fragment_key)?), None, fragment_key));
        }
        let target = source_of(&p.output, None, plan, caller);
        let path = self.prepare_native(p, &key, refl, samplers, native, target);
        let key = fragment_key;
        match path {
            Ok(path) if !matches!(p.output, Resource::Output) => Ok((None, Some(path), key)),
            Ok(path) => Ok((Some(render(self, &key)?), Some(path), key)),
            Err(d) => {
                log::info!(
                    "pass `{}` runs its @fragment entry point: {}",
                    p.path,
                    d.message
                );
                Ok((Some(render(self, &key)?), None, key))
            }
        }
    }

    pub fn prepare(
        &mut self,
        graph: &Graph,
        plan: Plan,
        sources: &mut SourceMap,
    ) -> Result<Prepared, ExecError> {
        self.prepare_cached(graph, plan, sources, &mut ShaderCache::default())
    }

    /// [`Engine::prepare`] with the shaders `cache` holds already, loaded for
    /// `sources` ([`crate::shader::preload_graph_shaders`], which needs no device).
    pub fn prepare_cached(
        &mut self,
        graph: &Graph,
        plan: Plan,
        sources: &mut SourceMap,
        cache: &mut ShaderCache,
    ) -> Result<Prepared, ExecError> {
        let start = Instant::now();
        let mut diags = Diagnostics::default();
        let (shaders, shader_diags) =
            load_plan_shaders_with(graph, &plan, sources, &self.shader_dirs, cache);
        diags.extend(shader_diags);
        // The passes' pipelines, built side by side; the passes below find them.
        self.prewarm(graph, &plan, &shaders);
        let mut passes = Vec::new();
        let mut caller = Vec::new();
        let mut stats = PreparedStats::default();
        for (pi, p) in plan.passes.iter().enumerate() {
            let span = p.node.map(|n| graph.pass(n).name_span);
            let at = |d: Diagnostic| match span {
                Some(s) => d.at(s, ""),
                None => d,
            };
            let target = match self.check_target(p) {
                Ok(target) => target,
                Err(d) => {
                    diags.push(at(d));
                    continue;
                }
            };
            let Some(loaded) = shaders[pi].clone() else {
                continue;
            };
            let Some(bindings) = self.pass_bindings(graph, p, &loaded.reflection, &mut diags)
            else {
                continue;
            };
            let built = self.build_pass(
                p,
                loaded,
                target,
                bindings,
                (&plan, &mut caller),
                &mut stats,
            );
            match built {
                Ok(gp) => passes.push(gp),
                Err(d) => diags.push(at(d)),
            }
        }
        if diags.has_errors() {
            diags.sort();
            return Err(ExecError::Rejected(diags));
        }
        let rings = self.create_rings(&plan);
        let timer = GpuTimer::new(&self.ctx, plan.passes.len() as u32);
        let mut prepared = Prepared::new(
            plan,
            passes,
            self.ctx.queue.clone(),
            caller,
            rings,
            timer,
            start.elapsed(),
            stats,
        );
        prepared.prebind(self);
        Ok(prepared)
    }

    /// The textures and samplers the shader of pass `p` declares, matched by name to
    /// the pass's inputs, with their filterability from the bound formats. `None` (and
    /// errors in `diags`) when an input is missing, or cannot be filtered or viewed as
    /// the pass asks on this adapter.
    pub(super) fn pass_bindings(
        &self,
        graph: &Graph,
        p: &PlannedPass,
        refl: &Reflection,
        diags: &mut Diagnostics,
    ) -> Option<PassBindings> {
        let adapter = &self.ctx.info.name;
        let span = p.node.map(|n| graph.pass(n).name_span);
        let at = |d: Diagnostic| match span {
            Some(s) => d.at(s, ""),
            None => d,
        };
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
                .note(format!(
                    "set `{}.FILTER = nearest`, or use a 16-bit float format",
                    inp.name
                ));
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
        let samplers = self.pass_samplers(p, refl);
        ok.then_some(PassBindings {
            textures,
            filterable,
            samplers,
        })
    }

    /// The sampling of each sampler the shader declares: its input's (`NAME_sampler`),
    /// filtering where that input's format can be filtered; else the default sampling,
    /// filtering when every input can be.
    fn pass_samplers(&self, p: &PlannedPass, refl: &Reflection) -> Vec<(u32, Sampling, bool)> {
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
        samplers
    }

    /// Pass `p` ready to record: its pipelines (render, compute, BGRA twin), uniform
    /// buffer, bound textures and samplers, and target. Caller images it reads are
    /// added to `caller`.
    fn build_pass(
        &mut self,
        p: &PlannedPass,
        loaded: LoadedShader,
        target: wgpu::TextureFormat,
        bindings: PassBindings,
        (plan, caller): (&Plan, &mut Vec<CallerRef>),
        stats: &mut PreparedStats,
    ) -> Result<GpuPass, Diagnostic> {
        let (wgsl, refl, layout) = (loaded.wgsl, loaded.reflection, loaded.layout);
        let PassBindings {
            textures,
            filterable,
            samplers,
        } = bindings;
        let key = PipelineKey {
            wgsl: wgsl.clone(),
            entry: refl.entry_point.clone(),
            target,
            filterable: filterable.clone(),
        };
        let (pipeline, native, key) =
            self.pass_pipelines(p, key, &refl, &samplers, plan, caller)?;
        let uniform = refl
            .uniform
            .as_ref()
            .map(|u| self.pass_uniform(p, u, &layout, image_sizes(plan), stats));
        let compute = match self.execution {
            _ if native.is_some() => native,
            // A compute-native pass drawn instead: its compute path failed.
            super::Execution::Compute if refl.compute.is_none() => {
                let storage_target = source_of(&p.output, None, plan, caller);
                self.prepare_compute(p, &key, &refl, &samplers, storage_target)
            }
            _ => None,
        };
        // A pass writing the caller's output may write a BGRA twin of it.
        let twin = match p.output {
            Resource::Output if pipeline.is_some() => {
                TwinPipeline::new(&key, &refl, &samplers, &p.path)
            }
            _ => None,
        };
        let textures = textures
            .iter()
            .map(|&(binding, ii)| {
                let inp = &p.inputs[ii];
                let format = view_format(inp.desc.format, inp.view);
                (
                    binding,
                    source_of(&inp.resource, format, plan, caller),
                    format,
                )
            })
            .collect();
        let samplers = samplers
            .iter()
            .map(|&(b, s, f)| (b, self.sampler(s, f)))
            .collect();
        let target_format = view_format(p.desc.format, p.target_view);
        let target = source_of(&p.output, target_format, plan, caller);
        let mut gp = GpuPass::new(
            p.path.clone(),
            pipeline,
            textures,
            samplers,
            uniform,
            (target, target_format),
        );
        gp.twin = twin;
        gp.compute = compute;
        Ok(gp)
    }

    /// Whether the adapter can run pass `p` at all: its size, and the format its
    /// target is written in. Returns that format.
    pub(super) fn check_target(&self, p: &PlannedPass) -> Result<wgpu::TextureFormat, Diagnostic> {
        let max = self.ctx.device.limits().max_texture_dimension_2d;
        let adapter = &self.ctx.info.name;
        if p.desc.width > max || p.desc.height > max {
            return Err(Diagnostic::error(format!(
                "pass `{}` is {}x{} px; this adapter ({adapter}) allows at most {max} px on a side",
                p.path, p.desc.width, p.desc.height
            )));
        }
        let target =
            view_format(p.desc.format, p.target_view).unwrap_or(wgpu_format(p.desc.format));
        if p.target_view != View::Natural && self.ctx.info.backend == wgpu::Backend::Gl {
            return Err(Diagnostic::error(format!(
                "pass `{}` writes sRGB-encoded values to an sRGB target, which needs a texture view the GL backend cannot make",
                p.path
            ))
            .note("use the Vulkan backend (lavapipe) or write linear values"));
        }
        if !self.ctx.format_support(target).render {
            return Err(Diagnostic::error(format!(
                "pass `{}` renders to {}, which this adapter ({adapter}) cannot render to",
                p.path, p.desc.format
            ))
            .note("choose another OUT.FORMAT, e.g. rgba16f"));
        }
        Ok(target)
    }

    /// The uniform buffer of pass `p`, with its static values (sizes, the
    /// default camera) written once, here.
    fn pass_uniform(
        &self,
        p: &PlannedPass,
        u: &UniformBlock,
        layout: &UniformLayout,
        (in_size, final_size): ((u32, u32), (u32, u32)),
        stats: &mut PreparedStats,
    ) -> PassUniform {
        let buffer = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{} uniforms", p.path)),
            size: u64::from(layout.size.max(16)).next_multiple_of(16),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let std = StdContext {
            out_size: (p.desc.width, p.desc.height),
            input_sizes: p
                .inputs
                .iter()
                .map(|i| (i.desc.width, i.desc.height))
                .collect(),
            near: NO_CAMERA.near,
            far: NO_CAMERA.far,
            proj: NO_CAMERA.proj,
            inv_proj: NO_CAMERA.inv_proj,
            in_size,
            final_size,
            ..Default::default()
        };
        // Static values are written once, here.
        let written = layout.write(&std);
        self.ctx.queue.write_buffer(&buffer, 0, &written);
        stats.uniform_writes += 1;
        let per_frame = layout.is_dynamic();
        PassUniform {
            binding: u.binding,
            layout: layout.clone(),
            members: u.members.clone(),
            buffer,
            std,
            per_frame,
            written,
        }
    }

    /// The textures of the plan's feedback rings, each `depth + 1` deep.
    fn create_rings(&mut self, plan: &Plan) -> Vec<Vec<PooledTexture>> {
        let gl = self.is_gl();
        plan.rings
            .iter()
            .map(|r| {
                (0..=r.depth)
                    .map(|i| {
                        PooledTexture::create(
                            &self.ctx.device,
                            gl,
                            &format!("{} history {i}", r.pass),
                            r.desc,
                            self.ids.next(),
                            self.pool.stores(r.desc.format),
                        )
                    })
                    .collect()
            })
            .collect()
    }
}

/// The sizes of the effect's input and output images.
fn image_sizes(plan: &Plan) -> ((u32, u32), (u32, u32)) {
    let input = (plan.input.width, plan.input.height);
    let output = plan
        .passes
        .iter()
        .find(|p| p.output == Resource::Output)
        .map_or(input, |p| (p.desc.width, p.desc.height));
    (input, output)
}
