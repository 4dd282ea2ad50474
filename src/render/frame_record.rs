//! Recording one frame's passes (`frame.rs` runs the steps in order): the
//! shared inputs, each technique's passes, the background and transparency,
//! the AUX resolve and the object motion vectors, through one render-pass
//! helper that names and times every pass.

use super::cluster_gpu::GpuClusters;
use super::environment::EnvironmentLighting;
use super::light_compute::{ComputeLighting, LightCompute, LightComputeGroups, AUX_HALVES};
use super::lights::{FrameLists, LightVolumes};
use super::material::{MaterialSet, VariantMode};
use super::motion::{MotionCameras, MotionPass};
use super::options::RendererOptions;
use super::pipelines::{GeoKey, GeoPass, Layouts, LightPipe, Pipelines};
use super::shadow_pass::ShadowMaps;
use super::targets::Targets;
use super::technique::Technique;
use super::upload::{Batch, Geometry, MaterialResources};
use super::visibility::VisibilityBuffer;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
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
    pub light_view: &'a super::light_view_gpu::LightView,
    pub volumes: &'a LightVolumes,
    pub motion: &'a MotionPass,
    /// Deferred shading's visibility buffer, when it has one.
    pub visibility: Option<&'a VisibilityBuffer>,
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

/// Whether the AUX resolve's half `which` is a compute dispatch
/// ([`LightCompute::aux_in_compute`]).
pub(super) fn computes_aux(r: &FrameGpu<'_>, which: LightCompute) -> bool {
    which.aux_in_compute(r.opts.compute_lighting, r.layouts)
}

/// The compute light pass of `technique`.
pub(super) fn light_compute_of(technique: Technique) -> LightCompute {
    match technique {
        Technique::Deferred => LightCompute::Compose,
        _ => LightCompute::Prepass,
    }
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
    /// Loaded and written (drawn over the visibility buffer's depth).
    Load,
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
        Depth::Clear | Depth::Load => Some(wgpu::RenderPassDepthStencilAttachment {
            view: &t.depth.view,
            depth_ops: Some(wgpu::Operations {
                load: match depth {
                    Depth::Clear => wgpu::LoadOp::Clear(1.0),
                    _ => wgpu::LoadOp::Load,
                },
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

type Colors<'a> = [Option<wgpu::RenderPassColorAttachment<'a>>];

/// One frame being recorded: what its passes read, and the timed pass names
/// and draw calls so far.
pub(super) struct Recorder<'a> {
    r: &'a FrameGpu<'a>,
    p: &'a FramePipelines<'a>,
    t: &'a Targets,
    technique: Technique,
    fl: &'a FrameLists,
    timer: Option<&'a GpuTimer>,
    /// The lights run as the compute pass (`light_compute.rs`).
    compute: bool,
    /// Transparent instances, far to near.
    blend: Vec<&'a Batch>,
    names: Vec<String>,
    draws: usize,
}

impl<'a> Recorder<'a> {
    pub fn new(
        (r, p, t): (&'a FrameGpu<'a>, &'a FramePipelines<'a>, &'a Targets),
        technique: Technique,
        fl: &'a FrameLists,
        view: &Mat4,
        timer: Option<&'a GpuTimer>,
        compute: bool,
    ) -> Recorder<'a> {
        let mut blend: Vec<(f32, &Batch)> = r
            .geometry
            .blend_items
            .iter()
            .map(|b| (view.transform_point3(b.center).z, &b.batch))
            .collect();
        blend.sort_by(|a, b| a.0.total_cmp(&b.0));
        Recorder {
            r,
            p,
            t,
            technique,
            fl,
            timer,
            compute,
            blend: blend.into_iter().map(|(_, b)| b).collect(),
            names: Vec::new(),
            draws: 0,
        }
    }

    /// What every later pass reads: the skinned and morphed vertices, the
    /// shadow maps (the layers that changed) and the cluster lists (built on
    /// the GPU; the light passes and forward read them).
    pub fn shared_inputs(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let r = self.r;
        if let Some(skinning) = &r.geometry.skinning {
            skinning.encode(encoder, &mut self.names, self.timer);
        }
        self.draws += r
            .shadow_maps
            .encode(encoder, r.geometry, &mut self.names, self.timer);
        if self.fl.clustered {
            let inputs = (r.light_view, self.timer);
            r.clusters.encode(encoder, &mut self.names, inputs);
        }
    }

    /// The technique's own passes, up to the lit HDR scene.
    pub fn technique_passes(&mut self, encoder: &mut wgpu::CommandEncoder) {
        match self.technique {
            Technique::Deferred => self.deferred(encoder),
            Technique::LightPrepass => self.light_prepass(encoder),
            Technique::Forward => self.forward(encoder),
        }
    }

    /// Deferred: the G-buffer, the lights, the composition (in the compute
    /// light pass's dispatch when it runs).
    fn deferred(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let t = self.t;
        let zero = clear_to(Vec4::ZERO);
        // the compute light pass adds the lights to what this pass starts the
        // specular light with
        let start = if self.compute {
            &t.emission
        } else {
            &t.light_specular
        };
        let (ops, depth) = match self.r.visibility {
            // the resolve filled the G-buffer: its other draws over it
            Some(v) => {
                let (r, names) = (self.r, &mut self.names);
                let inputs = (r.g0, r.geometry, r.material_gpu);
                self.draws += v.encode(encoder, inputs, t, self.compute, (names, self.timer));
                (LOAD, Depth::Load)
            }
            None => (zero, Depth::Clear),
        };
        let colors = [
            attach(&t.albedo.view, ops),
            attach(&t.normal.view, ops),
            attach(&t.specular.view, ops),
            attach(&start.view, ops),
        ];
        if self.r.visibility.is_none_or(|v| v.has_fallback()) {
            self.geometry(encoder, "geometry", &colors, depth, GeoPass::GBuffer);
        }
        self.light_pass(encoder, LOAD);
        if !self.compute {
            let colors = [attach(&t.scene.view, zero)];
            self.fullscreen(encoder, "composition", LightPipe::Compose, &colors);
        }
    }

    /// Light pre-pass: depth and normals, the lights, the final geometry.
    fn light_prepass(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let t = self.t;
        let zero = clear_to(Vec4::ZERO);
        let colors = [
            attach(&t.albedo.view, zero),
            attach(&t.normal.view, zero),
            attach(&t.specular.view, zero),
        ];
        self.geometry(
            encoder,
            "depth+normals",
            &colors,
            Depth::Clear,
            GeoPass::Prepass,
        );
        self.light_pass(encoder, zero);
        let background = clear_to(self.r.environment.clear_color(self.r.frame_background));
        let colors = [
            attach(&t.scene.view, background),
            attach(&t.albedo.view, LOAD),
        ];
        self.geometry(
            encoder,
            "final geometry",
            &colors,
            Depth::Read,
            GeoPass::LppFinal,
        );
    }

    /// Forward: one geometry pass that lights as it draws (the colour targets
    /// feed the AUX images).
    fn forward(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let t = self.t;
        let zero = clear_to(Vec4::ZERO);
        let background = clear_to(self.r.environment.clear_color(self.r.frame_background));
        let colors = [
            attach(&t.scene.view, background),
            attach(&t.albedo.view, zero),
            attach(&t.normal.view, zero),
            attach(&t.specular.view, zero),
        ];
        self.geometry(encoder, "forward", &colors, Depth::Clear, GeoPass::Forward);
    }

    /// The environment behind the geometry (deferred draws it in the
    /// composition) and the transparent instances, far to near.
    pub fn background_and_transparency(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let t = self.t;
        if self.technique != Technique::Deferred && self.r.environment.background_pass() {
            let colors = [attach(&t.scene.view, LOAD)];
            self.fullscreen(encoder, "background", LightPipe::Background, &colors);
        }
        if !self.blend.is_empty() {
            let colors = [attach(&t.scene.view, LOAD)];
            self.geometry(
                encoder,
                "transparency",
                &colors,
                Depth::Read,
                GeoPass::ForwardBlend,
            );
        }
    }

    /// The AUX images from the G-buffer (motion: of the camera alone; the
    /// moved instances are drawn over it by [`Recorder::object_motion`]), in
    /// two halves, each a compute dispatch where [`computes_aux`] says so
    /// (the second's albedo then copied from its raw twin), else drawn.
    pub fn aux_resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let (r, p, t) = (self.r, self.p, self.t);
        let groups = [&t.bg_aux_compute, &t.bg_aux_b_compute];
        for ((which, name, images, pipe), outputs) in AUX_HALVES.into_iter().zip(groups) {
            let Some(outputs) = outputs.as_ref().filter(|_| computes_aux(r, which)) else {
                let zero = clear_to(Vec4::ZERO);
                let targets: Vec<_> = images
                    .iter()
                    .map(|&i| attach(&t.aux[i].1.view, zero))
                    .collect();
                self.fullscreen(encoder, name, pipe, &targets);
                continue;
            };
            let groups = LightComputeGroups {
                g0: r.g0,
                gbuffer: &t.bg_all,
                outputs,
                params: &r.material_gpu.params_group,
            };
            let (size, names) = ((t.width, t.height), &mut self.names);
            p.light_compute
                .encode(encoder, which, &groups, size, name, names, self.timer);
            if which == LightCompute::AuxResolveB {
                t.copy_aux_albedo(encoder);
            }
        }
    }

    /// The moved instances' motion vectors over the resolve pass's camera
    /// motion (AUX.motion, the last aux image). Returns its draw calls.
    pub fn object_motion(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        motion: &MotionCameras,
        moving: &[Batch],
    ) -> Result<usize, GpuError> {
        let (r, t) = (self.r, self.t);
        let first = self.names.len() as u32;
        if !moving.is_empty() {
            self.names.push("motion (objects)".into());
        }
        let (_, motion_target) = t.aux.last().expect("AUX.motion exists");
        r.motion.encode(
            ctx,
            encoder,
            r.geometry,
            motion,
            (t.width, t.height),
            &t.depth.view,
            &motion_target.view,
            moving,
            self.timer.map(|t| (t, first)),
        )
    }

    /// Resolves the timestamps; returns the timed pass names and the draws.
    pub fn finish(self, encoder: &mut wgpu::CommandEncoder) -> (Vec<String>, usize) {
        if let Some(timer) = self.timer {
            timer.resolve(encoder, self.names.len() as u32);
        }
        (self.names, self.draws)
    }

    /// The light pass: the compute dispatch, or the fragment pass with the
    /// cluster lists or the light volumes.
    fn light_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        specular_ops: wgpu::Operations<wgpu::Color>,
    ) {
        let (r, p, t) = (self.r, self.p, self.t);
        if self.compute {
            p.light_compute.encode(
                encoder,
                light_compute_of(self.technique),
                &LightComputeGroups {
                    g0: r.g0,
                    gbuffer: &t.bg_light,
                    outputs: match self.technique {
                        Technique::Deferred => &t.bg_compute_deferred,
                        _ => &t.bg_compute_prepass,
                    },
                    params: &r.material_gpu.params_group,
                },
                (t.width, t.height),
                "lights",
                &mut self.names,
                self.timer,
            );
            return;
        }
        let colors = [
            attach(&t.light_diffuse.view, clear_to(Vec4::ZERO)),
            attach(&t.light_specular.view, specular_ops),
        ];
        let mut rp = begin(
            encoder,
            t,
            &mut self.names,
            self.timer,
            "lights",
            &colors,
            Depth::Read,
        );
        rp.set_bind_group(0, r.g0, &[]);
        rp.set_bind_group(1, &t.bg_light, &[]);
        rp.set_bind_group(3, &r.material_gpu.params_group, &[]);
        if self.fl.clustered {
            rp.set_pipeline(p.pipelines.light_cached(LightPipe::Clustered));
            rp.draw(0..3, 0..1);
            self.draws += 1;
            return;
        }
        self.draws += light_volumes((r, p), self.fl, &mut rp);
    }

    /// A full-screen fragment pass of the light module's `pipe`.
    fn fullscreen(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        name: &str,
        pipe: LightPipe,
        colors: &Colors<'_>,
    ) {
        let (r, p, t) = (self.r, self.p, self.t);
        let mut rp = begin(
            encoder,
            t,
            &mut self.names,
            self.timer,
            name,
            colors,
            Depth::None,
        );
        rp.set_pipeline(p.pipelines.light_cached(pipe));
        rp.set_bind_group(0, r.g0, &[]);
        rp.set_bind_group(1, &t.bg_all, &[]);
        rp.set_bind_group(3, &r.material_gpu.params_group, &[]);
        rp.draw(0..3, 0..1);
        self.draws += 1;
    }

    /// A geometry pass: every opaque batch, or the sorted transparent ones.
    fn geometry(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        name: &str,
        colors: &Colors<'_>,
        depth: Depth,
        pass: GeoPass,
    ) {
        let (r, p, t) = (self.r, self.p, self.t);
        let lights = self.fl.forward_lights;
        let mut rp = begin(encoder, t, &mut self.names, self.timer, name, colors, depth);
        if pass == GeoPass::LppFinal {
            rp.set_bind_group(1, &t.bg_final, &[]);
        }
        let draws = &mut self.draws;
        if pass == GeoPass::ForwardBlend {
            let blend = self.blend.iter().copied();
            draw_batches((r, p), &mut rp, blend, pass, lights, draws);
        } else {
            // the visibility buffer resolved some G-buffer draws already
            let vis = r.visibility.filter(|_| pass == GeoPass::GBuffer);
            let batches = r.geometry.batches.iter().enumerate();
            let batches = batches.filter(|(i, _)| vis.is_none_or(|v| !v.resolves(*i)));
            draw_batches(
                (r, p),
                &mut rp,
                batches.map(|(_, b)| b),
                pass,
                lights,
                draws,
            );
        }
    }
}

/// The light volumes of the fragment light pass (light culling `volumes`):
/// the full-screen lights, then the spheres and cones seen from outside and
/// from inside. Returns the draw calls.
fn light_volumes(
    (r, p): (&FrameGpu<'_>, &FramePipelines<'_>),
    fl: &FrameLists,
    rp: &mut wgpu::RenderPass<'_>,
) -> usize {
    let mut draws = 0;
    if !fl.fullscreen.is_empty() {
        rp.set_pipeline(p.pipelines.light_cached(LightPipe::Fullscreen));
        rp.draw(0..3, fl.fullscreen.clone());
        draws += 1;
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
            draws += 1;
        }
        if !cones.is_empty() {
            rp.draw_indexed(
                r.volumes.cone_indices.clone(),
                r.volumes.cone_base_vertex,
                cones.clone(),
            );
            draws += 1;
        }
    }
    draws
}
