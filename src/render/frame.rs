//! Encoding one frame: the passes of each technique (deferred, light pre-pass,
//! forward), transparency and the AUX resolve, through one render-pass helper.

use super::cluster_gpu::GpuClusters;
use super::environment::EnvironmentLighting;
use super::error::RenderError;
use super::frame_record::Recorder;
use super::light_compute::{ComputeLighting, LightCompute};
use super::lights::{FrameLists, LightVolumes};
use super::material::{MaterialSet, VariantMode};
use super::motion::{MotionCameras, MotionPass};
use super::options::RendererOptions;
use super::pipelines::{GeoKey, GeoPass, Layouts, LightPipe, Pipelines};
use super::shadow_pass::ShadowMaps;
use super::targets::Targets;
use super::technique::Technique;
use super::upload::{Batch, Geometry, MaterialResources};
use crate::gpu::context::{GpuContext, GpuTimer};
use glam::{Mat4, Vec3};

/// What a frame is encoded with: the renderer's scene resources, borrowed
/// (the pipelines come separately: creating them needs them mutable).
pub(crate) struct FrameGpu<'a> {
    pub opts: &'a RendererOptions,
    /// The AUX images and their formats.
    pub aux_formats: &'a [(String, crate::script::types::Format)],
    pub materials: &'a MaterialSet,
    pub geometry: &'a Geometry,
    pub material_gpu: &'a MaterialResources,
    pub layouts: &'a Layouts,
    pub environment: &'a EnvironmentLighting,
    pub g0: &'a wgpu::BindGroup,
    pub shadow_maps: &'a ShadowMaps,
    pub clusters: &'a GpuClusters,
    pub volumes: &'a LightVolumes,
    pub motion: &'a MotionPass,
    /// The frame's background colour (fogged).
    pub frame_background: Vec3,
}

/// The pipelines a frame draws with.
pub(crate) struct FramePipelines<'a> {
    pub pipelines: &'a Pipelines,
    pub light_compute: &'a ComputeLighting,
}

pub(super) fn geo_key(
    materials: &MaterialSet,
    mode: VariantMode,
    pass: GeoPass,
    b: &Batch,
    lights: u32,
) -> GeoKey {
    let m = &materials.materials[b.material];
    let features = match mode {
        super::material::VariantMode::Branch => 0,
        _ => b.features,
    };
    GeoKey {
        pass,
        variant: super::material::VariantKey {
            surface: m.surface,
            lighting: m.lighting,
            features,
        },
        cull: b.cull,
        lights: match pass {
            GeoPass::Forward | GeoPass::ForwardBlend => match mode {
                super::material::VariantMode::Branch => 0,
                _ => lights,
            },
            _ => 0,
        },
    }
}

/// The geometry passes a technique draws opaque batches with.
fn opaque_passes(technique: Technique) -> &'static [GeoPass] {
    match technique {
        Technique::Deferred => &[GeoPass::GBuffer],
        Technique::LightPrepass => &[GeoPass::Prepass, GeoPass::LppFinal],
        Technique::Forward => &[GeoPass::Forward],
    }
}

/// Whether `technique` lights in a compute pass ([`super::light_compute`]):
/// deferred and light pre-pass with cluster lists, unless the options ask for
/// the fragment pass.
fn computes_lights(opts: &RendererOptions, technique: Technique) -> bool {
    technique != Technique::Forward
        && opts.compute_lighting
        && opts.light_culling != super::clusters::LightCulling::Volumes
}

/// The compute light pass of `technique`.
pub(super) fn light_compute_of(technique: Technique) -> LightCompute {
    match technique {
        Technique::Deferred => LightCompute::Compose,
        _ => LightCompute::Prepass,
    }
}

/// Creates every pipeline the frame needs (shader generation errors are material
/// errors: they name the material's shaders).
pub(crate) fn ensure_pipelines(
    r: &FrameGpu<'_>,
    (pipelines, light_compute): (&mut Pipelines, &mut ComputeLighting),
    ctx: &GpuContext,
    technique: Technique,
    lights: u32,
) -> Result<(), String> {
    let mut keys: Vec<(GeoKey, usize)> = Vec::new();
    for b in &r.geometry.batches {
        for &pass in opaque_passes(technique) {
            keys.push((
                geo_key(r.materials, pipelines.mode, pass, b, lights),
                r.materials.materials[b.material].surface,
            ));
        }
    }
    for item in &r.geometry.blend_items {
        let b = &item.batch;
        keys.push((
            geo_key(
                r.materials,
                pipelines.mode,
                GeoPass::ForwardBlend,
                b,
                lights,
            ),
            r.materials.materials[b.material].surface,
        ));
    }
    for (key, surface) in keys {
        pipelines.geometry(
            ctx,
            r.materials,
            r.layouts,
            &r.material_gpu.layouts[surface],
            &r.material_gpu.params_layout,
            key,
        )?;
    }
    let aux: Vec<(String, wgpu::TextureFormat)> = r
        .aux_formats
        .iter()
        .map(|(n, f)| (n.clone(), crate::gpu::executor::wgpu_format(*f)))
        .collect();
    let mut light = vec![LightPipe::AuxA, LightPipe::AuxB];
    let compute = computes_lights(r.opts, technique);
    if compute {
        light_compute.ensure(
            ctx,
            pipelines,
            r.materials,
            (r.layouts, &r.material_gpu.params_layout),
            light_compute_of(technique),
        )?;
    } else if technique != Technique::Forward {
        if r.opts.light_culling == super::clusters::LightCulling::Volumes {
            light.extend([
                LightPipe::Fullscreen,
                LightPipe::VolumeFront,
                LightPipe::VolumeBack,
            ]);
        } else {
            light.push(LightPipe::Clustered);
        }
    }
    if technique == Technique::Deferred {
        if !compute {
            light.push(LightPipe::Compose);
        }
    } else if r.environment.background_pass() {
        light.push(LightPipe::Background);
    }
    for which in light {
        pipelines.light(
            ctx,
            r.materials,
            r.layouts,
            &r.material_gpu.params_layout,
            &aux,
            which,
        )?;
    }
    Ok(())
}

/// Encodes and submits the frame, as steps (`frame_record.rs`): the inputs
/// every pass reads (skinned vertices, shadow maps, cluster lists), the
/// technique's passes, the background and transparency, the AUX resolve, and
/// the moved instances' motion vectors. Returns the timed pass names and the
/// draw count.
#[allow(clippy::too_many_arguments)]
pub(crate) fn encode(
    (r, p, t): (&FrameGpu<'_>, &FramePipelines<'_>, &Targets),
    ctx: &GpuContext,
    label: &str,
    technique: Technique,
    fl: &FrameLists,
    view: &Mat4,
    timer: Option<&GpuTimer>,
    (motion, moving): (&MotionCameras, &[Batch]),
) -> Result<(Vec<String>, usize), RenderError> {
    let compute = computes_lights(r.opts, technique) && fl.clustered;
    let mut result = Ok((Vec::new(), 0));
    ctx.scoped(label, |device| {
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        let mut rec = Recorder::new((r, p, t), technique, fl, view, timer, compute);
        rec.shared_inputs(&mut encoder);
        rec.technique_passes(&mut encoder);
        rec.background_and_transparency(&mut encoder);
        rec.aux_resolve(&mut encoder);
        let motion_draws = rec.object_motion(ctx, &mut encoder, motion, moving);
        let (names, draws) = rec.finish(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        result = motion_draws.map(|m| (names, draws + m));
    })?;
    Ok(result?)
}
