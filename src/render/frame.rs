//! Encoding one frame: the pipelines it needs, and its passes in order (the
//! recording itself is `frame_record.rs`).

use super::error::RenderError;
use super::frame_record::{computes_aux, geo_key, light_compute_of, Recorder};
pub(crate) use super::frame_record::{FrameGpu, FramePipelines};
use super::light_compute::{ComputeLighting, LightCompute};
use super::lights::FrameLists;
use super::motion::MotionCameras;
use super::options::RendererOptions;
use super::pipelines::{GeoKey, GeoPass, LightPipe, Pipelines};
use super::targets::Targets;
use super::technique::Technique;
use super::upload::Batch;
use crate::gpu::context::{GpuContext, GpuTimer};
use glam::Mat4;

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

/// The geometry pipelines of `technique` (with a forward loop of `lights`):
/// one per opaque batch and pass, one per transparent instance; each with its
/// material's surface shader.
fn geometry_keys(
    r: &FrameGpu<'_>,
    mode: super::material::VariantMode,
    technique: Technique,
    lights: u32,
) -> Vec<(GeoKey, usize)> {
    let mut keys: Vec<(GeoKey, usize)> = Vec::new();
    for (i, b) in r.geometry.batches.iter().enumerate() {
        for &pass in opaque_passes(technique) {
            if pass == GeoPass::GBuffer && r.visibility.is_some_and(|v| v.resolves(i)) {
                continue;
            }
            keys.push((
                geo_key(r.materials, mode, pass, b, lights),
                r.materials.materials[b.material].surface,
            ));
        }
    }
    for item in &r.geometry.blend_items {
        let b = &item.batch;
        keys.push((
            geo_key(r.materials, mode, GeoPass::ForwardBlend, b, lights),
            r.materials.materials[b.material].surface,
        ));
    }
    keys
}

/// The light-module pipelines of `technique`: the AUX resolve; the light
/// pass's unless it runs in compute (`compute`) or forward; composition
/// (deferred in fragments) or the background (the other techniques, when the
/// environment draws one).
fn light_pipes(r: &FrameGpu<'_>, technique: Technique, compute: bool) -> Vec<LightPipe> {
    let mut light = Vec::new();
    for (which, pipe) in [
        (LightCompute::AuxResolveB, LightPipe::AuxB),
        (LightCompute::AuxResolve, LightPipe::AuxA),
    ] {
        if !computes_aux(r, which) {
            light.push(pipe);
        }
    }
    if !compute && technique != Technique::Forward {
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
    light
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
    for (key, surface) in geometry_keys(r, pipelines.mode, technique, lights) {
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
    let compute = computes_lights(r.opts, technique);
    let dispatches = [
        compute.then_some(light_compute_of(technique)),
        computes_aux(r, LightCompute::AuxResolve).then_some(LightCompute::AuxResolve),
        computes_aux(r, LightCompute::AuxResolveB).then_some(LightCompute::AuxResolveB),
    ];
    for which in dispatches.into_iter().flatten() {
        light_compute.ensure(
            ctx,
            pipelines,
            r.materials,
            (r.layouts, &r.material_gpu.params_layout),
            which,
        )?;
    }
    for which in light_pipes(r, technique, compute) {
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
