//! Encoding one frame: the passes of each technique (deferred, light pre-pass,
//! forward), transparency and the AUX resolve, through one render-pass helper.

use super::cluster_gpu::GpuClusters;
use super::environment::EnvironmentLighting;
use super::error::RenderError;
use super::light_compute::{ComputeLighting, LightCompute, LightComputeGroups};
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
use glam::{Mat4, Vec3, Vec4};

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

fn geo_key(
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
fn light_compute_of(technique: Technique) -> LightCompute {
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

fn attach(
    view: &wgpu::TextureView,
    ops: wgpu::Operations<wgpu::Color>,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops,
    })
}

fn clear_to(c: Vec4) -> wgpu::Operations<wgpu::Color> {
    wgpu::Operations {
        load: wgpu::LoadOp::Clear(wgpu::Color {
            r: f64::from(c.x),
            g: f64::from(c.y),
            b: f64::from(c.z),
            a: f64::from(c.w),
        }),
        store: wgpu::StoreOp::Store,
    }
}

const LOAD: wgpu::Operations<wgpu::Color> = wgpu::Operations {
    load: wgpu::LoadOp::Load,
    store: wgpu::StoreOp::Store,
};

/// How a pass uses the depth buffer.
#[derive(Clone, Copy, PartialEq)]
enum Depth {
    None,
    /// Cleared to 1 and written.
    Clear,
    /// Attached read-only (the pass also samples it).
    Read,
}

/// Begins a render pass with `colors`, the depth attachment as `depth`, and the
/// pass's timestamp named `name`.
fn begin<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    t: &'e Targets,
    names: &mut Vec<String>,
    timer: Option<&'e GpuTimer>,
    name: &str,
    colors: &[Option<wgpu::RenderPassColorAttachment<'e>>],
    depth: Depth,
) -> wgpu::RenderPass<'e> {
    let i = names.len() as u32;
    names.push(name.to_string());
    let depth_stencil_attachment = match depth {
        Depth::None => None,
        Depth::Clear => Some(wgpu::RenderPassDepthStencilAttachment {
            view: &t.depth.view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        Depth::Read => Some(wgpu::RenderPassDepthStencilAttachment {
            view: &t.depth.view,
            depth_ops: None,
            stencil_ops: None,
        }),
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(name),
        color_attachments: colors,
        depth_stencil_attachment,
        timestamp_writes: timer.and_then(|t| t.pass_writes(i)),
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Draws `batches` with the pipeline of each, switching pipelines and material
/// bind groups only when they change.
fn draw_batches<'a>(
    (r, p): (&FrameGpu<'_>, &FramePipelines<'_>),
    rp: &mut wgpu::RenderPass<'_>,
    batches: impl Iterator<Item = &'a Batch>,
    pass: GeoPass,
    lights: u32,
    draws: &mut usize,
) {
    rp.set_bind_group(0, r.g0, &[]);
    rp.set_bind_group(3, &r.material_gpu.params_group, &[]);
    rp.set_vertex_buffer(0, r.geometry.vertex_buffer.slice(..));
    rp.set_index_buffer(r.geometry.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
    let mut current_key: Option<GeoKey> = None;
    let mut current_material: Option<(usize, u64)> = None;
    for b in batches {
        let key = geo_key(r.materials, p.pipelines.mode, pass, b, lights);
        if current_key != Some(key) {
            rp.set_pipeline(p.pipelines.geo_cached(&key));
            current_key = Some(key);
        }
        if current_material != Some((b.material, b.features)) {
            rp.set_bind_group(2, r.material_gpu.group(b.material, b.features), &[]);
            current_material = Some((b.material, b.features));
        }
        rp.draw_indexed(b.indices.clone(), b.base_vertex, b.instances.clone());
        *draws += 1;
    }
}

/// Encodes and submits the frame. Returns the timed pass names and the draw count.
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
    let mut names: Vec<String> = Vec::new();
    let mut draws = 0usize;
    let lights = fl.forward_lights;
    // Transparent instances, far to near.
    let mut blend: Vec<(f32, &Batch)> = r
        .geometry
        .blend_items
        .iter()
        .map(|b| (view.transform_point3(b.center).z, &b.batch))
        .collect();
    blend.sort_by(|a, b| a.0.total_cmp(&b.0));
    let background = clear_to(r.environment.clear_color(r.frame_background));
    let compute = computes_lights(r.opts, technique) && fl.clustered;
    let zero = clear_to(Vec4::ZERO);
    let mut motion_result = Ok(0);
    ctx.scoped(label, |device| {
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        // Skinned and morphed vertices first: every pass below draws them.
        if let Some(skinning) = &r.geometry.skinning {
            skinning.encode(&mut encoder, &mut names, timer);
        }
        // Shadow maps next: every technique's light passes read them.
        draws += r
            .shadow_maps
            .encode(&mut encoder, r.geometry, &mut names, timer);
        // The cluster lists, built on the GPU: the light passes and forward
        // read them.
        if fl.clustered {
            r.clusters.encode(&mut encoder, &mut names, timer);
        }
        let light_pass = |encoder: &mut wgpu::CommandEncoder,
                          names: &mut Vec<String>,
                          specular_ops: wgpu::Operations<wgpu::Color>,
                          draws: &mut usize| {
            if compute {
                p.light_compute.encode(
                    encoder,
                    light_compute_of(technique),
                    &LightComputeGroups {
                        g0: r.g0,
                        gbuffer: &t.bg_light,
                        outputs: match technique {
                            Technique::Deferred => &t.bg_compute_deferred,
                            _ => &t.bg_compute_prepass,
                        },
                        params: &r.material_gpu.params_group,
                    },
                    (t.width, t.height),
                    "lights",
                    names,
                    timer,
                );
                return;
            }
            let mut rp = begin(
                encoder,
                t,
                names,
                timer,
                "lights",
                &[
                    attach(&t.light_diffuse.view, zero),
                    attach(&t.light_specular.view, specular_ops),
                ],
                Depth::Read,
            );
            rp.set_bind_group(0, r.g0, &[]);
            rp.set_bind_group(1, &t.bg_light, &[]);
            rp.set_bind_group(3, &r.material_gpu.params_group, &[]);
            if fl.clustered {
                rp.set_pipeline(p.pipelines.light_cached(LightPipe::Clustered));
                rp.draw(0..3, 0..1);
                *draws += 1;
                return;
            }
            if !fl.fullscreen.is_empty() {
                rp.set_pipeline(p.pipelines.light_cached(LightPipe::Fullscreen));
                rp.draw(0..3, fl.fullscreen.clone());
                *draws += 1;
            }
            rp.set_vertex_buffer(0, r.volumes.vertices.slice(..));
            rp.set_index_buffer(r.volumes.indices.slice(..), wgpu::IndexFormat::Uint32);
            for (pipe, spheres, cones) in [
                (LightPipe::VolumeFront, &fl.sphere_out, &fl.cone_out),
                (LightPipe::VolumeBack, &fl.sphere_in, &fl.cone_in),
            ] {
                if spheres.is_empty() && cones.is_empty() {
                    continue;
                }
                rp.set_pipeline(p.pipelines.light_cached(pipe));
                if !spheres.is_empty() {
                    rp.draw_indexed(r.volumes.sphere_indices.clone(), 0, spheres.clone());
                    *draws += 1;
                }
                if !cones.is_empty() {
                    rp.draw_indexed(
                        r.volumes.cone_indices.clone(),
                        r.volumes.cone_base_vertex,
                        cones.clone(),
                    );
                    *draws += 1;
                }
            }
        };
        let fullscreen = |encoder: &mut wgpu::CommandEncoder,
                          names: &mut Vec<String>,
                          name: &str,
                          pipe: LightPipe,
                          colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
                          draws: &mut usize| {
            let mut rp = begin(encoder, t, names, timer, name, colors, Depth::None);
            rp.set_pipeline(p.pipelines.light_cached(pipe));
            rp.set_bind_group(0, r.g0, &[]);
            rp.set_bind_group(1, &t.bg_all, &[]);
            rp.set_bind_group(3, &r.material_gpu.params_group, &[]);
            rp.draw(0..3, 0..1);
            *draws += 1;
        };
        // A geometry pass: every batch (opaque) or the sorted transparent ones.
        let geometry = |encoder: &mut wgpu::CommandEncoder,
                        names: &mut Vec<String>,
                        name: &str,
                        colors: &[Option<wgpu::RenderPassColorAttachment<'_>>],
                        depth: Depth,
                        pass: GeoPass,
                        draws: &mut usize| {
            let mut rp = begin(encoder, t, names, timer, name, colors, depth);
            if pass == GeoPass::LppFinal {
                rp.set_bind_group(1, &t.bg_final, &[]);
            }
            if pass == GeoPass::ForwardBlend {
                draw_batches(
                    (r, p),
                    &mut rp,
                    blend.iter().map(|(_, b)| *b),
                    pass,
                    lights,
                    draws,
                );
            } else {
                draw_batches(
                    (r, p),
                    &mut rp,
                    r.geometry.batches.iter(),
                    pass,
                    lights,
                    draws,
                );
            }
        };
        let (albedo, normal, specular) = (
            attach(&t.albedo.view, zero),
            attach(&t.normal.view, zero),
            attach(&t.specular.view, zero),
        );
        match technique {
            Technique::Deferred => {
                // the compute light pass adds the lights to what this pass
                // starts the specular light with
                let start = if compute {
                    &t.emission
                } else {
                    &t.light_specular
                };
                let colors = [albedo, normal, specular, attach(&start.view, zero)];
                geometry(
                    &mut encoder,
                    &mut names,
                    "geometry",
                    &colors,
                    Depth::Clear,
                    GeoPass::GBuffer,
                    &mut draws,
                );
                light_pass(&mut encoder, &mut names, LOAD, &mut draws);
                // (the compute light pass composes in the same dispatch)
                if !compute {
                    let colors = [attach(&t.scene.view, zero)];
                    fullscreen(
                        &mut encoder,
                        &mut names,
                        "composition",
                        LightPipe::Compose,
                        &colors,
                        &mut draws,
                    );
                }
            }
            Technique::LightPrepass => {
                let colors = [albedo, normal, specular];
                geometry(
                    &mut encoder,
                    &mut names,
                    "depth+normals",
                    &colors,
                    Depth::Clear,
                    GeoPass::Prepass,
                    &mut draws,
                );
                light_pass(&mut encoder, &mut names, zero, &mut draws);
                let colors = [
                    attach(&t.scene.view, background),
                    attach(&t.albedo.view, LOAD),
                ];
                geometry(
                    &mut encoder,
                    &mut names,
                    "final geometry",
                    &colors,
                    Depth::Read,
                    GeoPass::LppFinal,
                    &mut draws,
                );
            }
            Technique::Forward => {
                let colors = [attach(&t.scene.view, background), albedo, normal, specular];
                geometry(
                    &mut encoder,
                    &mut names,
                    "forward",
                    &colors,
                    Depth::Clear,
                    GeoPass::Forward,
                    &mut draws,
                );
            }
        }
        if technique != Technique::Deferred && r.environment.background_pass() {
            let colors = [attach(&t.scene.view, LOAD)];
            fullscreen(
                &mut encoder,
                &mut names,
                "background",
                LightPipe::Background,
                &colors,
                &mut draws,
            );
        }
        if !blend.is_empty() {
            let colors = [attach(&t.scene.view, LOAD)];
            geometry(
                &mut encoder,
                &mut names,
                "transparency",
                &colors,
                Depth::Read,
                GeoPass::ForwardBlend,
                &mut draws,
            );
        }
        for (pipe, range, name) in [
            (
                LightPipe::AuxA,
                [0, 1, 2, 6].as_slice(),
                "aux depth/normal/position/motion",
            ),
            (
                LightPipe::AuxB,
                [3, 4, 5].as_slice(),
                "aux albedo/material/specular",
            ),
        ] {
            let attachments: Vec<_> = range
                .iter()
                .map(|&i| attach(&t.aux[i].1.view, zero))
                .collect();
            fullscreen(
                &mut encoder,
                &mut names,
                name,
                pipe,
                &attachments,
                &mut draws,
            );
        }
        // The moved instances' motion vectors over the resolve pass's camera
        // motion (AUX.motion, the last aux image).
        let first = names.len() as u32;
        if !moving.is_empty() {
            names.push("motion (objects)".into());
        }
        let (_, motion_target) = t.aux.last().expect("AUX.motion exists");
        motion_result = r.motion.encode(
            ctx,
            &mut encoder,
            r.geometry,
            motion,
            (t.width, t.height),
            &t.depth.view,
            &motion_target.view,
            moving,
            timer.map(|t| (t, first)),
        );
        if let Some(timer) = timer {
            timer.resolve(&mut encoder, names.len() as u32);
        }
        ctx.queue.submit([encoder.finish()]);
    })?;
    draws += motion_result?;
    Ok((names, draws))
}
