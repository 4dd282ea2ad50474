//! The clustered light pass in compute (`fx_cs_light*` in
//! `shaders/render/light.wgsl`): one invocation per pixel in 8 × 8 tiles reads
//! the G-buffer once, shades the pixel's global and cluster lights (the lists
//! the GPU built, `cluster_gpu.rs`) with their shadows, and writes the two light
//! buffers once. Deferred shading composes in the same dispatch (diffuse colour
//! × diffuse light + specular light, fogged; the background where nothing was
//! drawn) and writes the HDR scene; the light pre-pass writes the light buffers
//! for its final geometry pass.
//!
//! Why: a full-screen fragment pass runs on the raster part of the chip, a
//! dispatch on all of it (`../shared/perf/README.md`: 20× on the H200 for a
//! copy). The maths is the fragment pass's (`fx_light_clustered` is shared),
//! so the fragment path ([`RendererOptions::compute_lighting`] off) is the
//! reference `tests/compute_lighting.rs` compares against.
//!
//! [`RendererOptions::compute_lighting`]: super::RendererOptions::compute_lighting

use super::pipelines::{Layouts, LightPipe, Pipelines};
use crate::gpu::context::{GpuContext, GpuTimer};
use std::collections::HashMap;

/// Pixels per side of a workgroup (as in light.wgsl).
const TILE: u32 = 8;

/// Which compute light pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum LightCompute {
    /// Light buffers only (light pre-pass).
    Prepass,
    /// Light buffers and the composed scene (deferred).
    Compose,
    /// AUX.depth, normal, position and camera motion from the G-buffer (the
    /// resolve's first half: `fx_cs_aux_a`).
    AuxResolve,
    /// AUX.albedo (sRGB-encoded into its raw twin), material and specular (the
    /// resolve's second half: `fx_cs_aux_b`).
    AuxResolveB,
}

impl LightCompute {
    fn entry_point(self) -> &'static str {
        match self {
            LightCompute::Prepass => "fx_cs_light",
            LightCompute::Compose => "fx_cs_light_compose",
            LightCompute::AuxResolve => "fx_cs_aux_a",
            LightCompute::AuxResolveB => "fx_cs_aux_b",
        }
    }
}

/// The AUX resolve's halves: the dispatch, the pass's name (as `--timings`
/// lists it), the AUX images it writes (by their index in `published_aux`)
/// and the fragment pass that draws them where the dispatch cannot run.
pub(crate) const AUX_HALVES: [(LightCompute, &str, &[usize], LightPipe); 2] = [
    (
        LightCompute::AuxResolve,
        "aux depth/normal/position/motion",
        &[0, 1, 2, 6],
        LightPipe::AuxA,
    ),
    (
        LightCompute::AuxResolveB,
        "aux albedo/material/specular",
        &[3, 4, 5],
        LightPipe::AuxB,
    ),
];

impl LightCompute {
    /// Whether the AUX resolve's half `self` is a compute dispatch: with
    /// compute lighting on, where the adapter can store to its images'
    /// formats (its group-2 layout exists); else a fragment pass draws it.
    pub fn aux_in_compute(self, compute_lighting: bool, layouts: &Layouts) -> bool {
        compute_lighting
            && match self {
                LightCompute::AuxResolve => layouts.g2_aux_compute.is_some(),
                LightCompute::AuxResolveB => layouts.g2_aux_b_compute.is_some(),
                _ => false,
            }
    }
}

/// The compute light pipelines of a renderer, created on first use.
#[derive(Default)]
pub(crate) struct ComputeLighting {
    pipelines: HashMap<LightCompute, wgpu::ComputePipeline>,
}

/// The bind groups of one dispatch.
pub(crate) struct LightComputeGroups<'a> {
    pub g0: &'a wgpu::BindGroup,
    pub gbuffer: &'a wgpu::BindGroup,
    pub outputs: &'a wgpu::BindGroup,
    pub params: &'a wgpu::BindGroup,
}

impl ComputeLighting {
    /// Creates the pipeline of `which` (from the light module of `pipelines`).
    pub fn ensure(
        &mut self,
        ctx: &GpuContext,
        pipelines: &mut Pipelines,
        set: &super::material::MaterialSet,
        (layouts, params_layout): (&Layouts, &wgpu::BindGroupLayout),
        which: LightCompute,
    ) -> Result<(), String> {
        if self.pipelines.contains_key(&which) {
            return Ok(());
        }
        let module = pipelines.light_module(ctx, set)?;
        let label = format!("deferred compute pipeline {which:?}");
        let outputs = match which {
            LightCompute::AuxResolve => layouts
                .g2_aux_compute
                .as_ref()
                .ok_or("the adapter cannot store to the AUX images' formats")?,
            LightCompute::AuxResolveB => layouts
                .g2_aux_b_compute
                .as_ref()
                .ok_or("the adapter cannot store to AUX.albedo/material/specular's formats")?,
            _ => &layouts.g2_light_compute,
        };
        let pipeline = ctx
            .scoped(&label, |device| {
                let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(&label),
                    bind_group_layouts: &[
                        Some(&layouts.g0),
                        Some(&layouts.g1_gbuffer),
                        Some(outputs),
                        Some(params_layout),
                    ],
                    immediate_size: 0,
                });
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(&label),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some(which.entry_point()),
                    compilation_options: Default::default(),
                    cache: ctx.pipeline_cache.as_ref(),
                })
            })
            .map_err(|e| e.to_string())?;
        pipelines.pipelines_created += 1;
        self.pipelines.insert(which, pipeline);
        Ok(())
    }

    /// Encodes the pass `which` over a `width`×`height` frame, named `name` in
    /// `names` and timed with `timer`.
    #[allow(clippy::too_many_arguments)] // the pass, its groups, its size, its timing
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        which: LightCompute,
        groups: &LightComputeGroups<'_>,
        (width, height): (u32, u32),
        name: &str,
        names: &mut Vec<String>,
        timer: Option<&GpuTimer>,
    ) {
        let index = names.len() as u32;
        names.push(name.to_string());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(name),
            timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
        });
        pass.set_pipeline(&self.pipelines[&which]);
        pass.set_bind_group(0, groups.g0, &[]);
        pass.set_bind_group(1, groups.gbuffer, &[]);
        pass.set_bind_group(2, groups.outputs, &[]);
        pass.set_bind_group(3, groups.params, &[]);
        pass.dispatch_workgroups(width.div_ceil(TILE), height.div_ceil(TILE), 1);
    }
}
