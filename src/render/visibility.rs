//! The visibility buffer ([`super::GbufferLayout::Visibility`]): deferred
//! shading's geometry stage as a raster pass that writes depth and one
//! `Rg32Uint` per pixel (the instance slot and `@builtin(primitive_index)`),
//! then one compute pass that resolves the materials into the G-buffer targets
//! the light pass already reads (`shaders/render/visibility_resolve.wgsl`): per
//! pixel, the triangle's corners read from the vertex and index buffers (the
//! skinning pass's output for deformed instances), the barycentrics of the ray
//! through the pixel, the corners' inputs interpolated and run through the
//! vertex stage's maths, texture gradients from the same triangle's plane at
//! the neighbouring pixels, and the surface shader. A classification dispatch
//! lists the 8 × 8 tiles of each (material, mesh features) pair
//! (`visibility_classify.wgsl`); each pair's resolve is an indirect dispatch
//! over its tiles, and a last one clears the pixels nothing was resolved at.
//! The sRGB targets are stored through raw `Rgba8Unorm` twins and copied in.
//!
//! Draws the resolve cannot take stay in a G-buffer pass drawn afterwards over
//! the same depth: alpha-tested (MASK) and layered (clear coat, transmission)
//! materials, and surfaces that take derivatives themselves (`dpdx`,
//! `fwidth`, `textureSampleBias`, ...; `visibility_shader.rs`).

use super::material::{variant, MaterialSet, VariantKey};
use super::pipelines::Layouts;
use super::targets::{Target, Targets};
use super::upload::{Cull, Geometry, MaterialResources};
use super::visibility_pipelines::{
    classify_layout, classify_pipelines, raster_pipeline, resolve_layout, resolve_pipeline,
    ID_FORMAT,
};
use super::visibility_shader::resolve_module;
use super::wgsl_check::check;
use crate::gpu::context::{GpuContext, GpuTimer};
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use wgpu::util::DeviceExt;

/// No triangle resolved at a pixel (the id target's clear value).
const NONE: u32 = u32::MAX;
/// Bytes between the dispatches' uniforms (the dynamic offset alignment).
const DISPATCH_STRIDE: u64 = 256;
/// Pixels per side of a resolve workgroup (as in the shader).
const TILE: u32 = 8;

/// `FxVisSlot`: where an instance slot's triangles are.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuVisSlot {
    first_index: u32,
    base_vertex: i32,
    group: u32,
    flags: u32,
}

/// One resolve dispatch: the material bind group and the pipeline.
struct ResolveGroup {
    material: usize,
    features: u64,
    pipeline: usize,
}

/// The per-size images and bind groups of the resolve.
struct VisTargets {
    size: (u32, u32),
    ids: Target,
    /// Raw twins of the sRGB albedo and specular targets.
    albedo: Target,
    specular: Target,
    /// Group 1 with the light written to the emission target (compute light
    /// pass) and to the specular light buffer (fragment light pass).
    groups: [wgpu::BindGroup; 2],
    /// The tile classification's group 0.
    classify: wgpu::BindGroup,
}

/// The tile classification (`visibility_classify.wgsl`): its pipelines
/// (tiles, arguments), layout, and the lists' counts and indirect arguments
/// (the tiles themselves are per size, in `VisTargets`).
struct Classify {
    pipelines: [wgpu::ComputePipeline; 2],
    layout: wgpu::BindGroupLayout,
    counts: wgpu::Buffer,
    args: wgpu::Buffer,
}

/// The visibility buffer of a renderer's scene.
pub(crate) struct VisibilityBuffer {
    /// Per opaque batch (`Geometry::batches`): resolved in compute, or drawn
    /// into the G-buffer afterwards.
    resolved: Vec<bool>,
    groups: Vec<ResolveGroup>,
    resolve: Vec<wgpu::ComputePipeline>,
    raster: HashMap<Cull, wgpu::RenderPipeline>,
    slots: wgpu::Buffer,
    dispatch: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    classify: Classify,
    targets: Option<VisTargets>,
}

/// Why the adapter or the scene cannot have a visibility buffer, if so.
fn unsupported(ctx: &GpuContext, geometry: &Geometry) -> Option<String> {
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::PRIMITIVE_INDEX)
    {
        return Some("the device has no `@builtin(primitive_index)`".into());
    }
    for f in [
        wgpu::TextureFormat::Rgb10a2Unorm,
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureFormat::Rgba16Float,
    ] {
        if !ctx.format_support(f).storage {
            return Some(format!("the adapter cannot store to {f:?} in compute"));
        }
    }
    let max = ctx.device.limits().max_storage_buffer_binding_size;
    if geometry.vertex_buffer.size() > max || geometry.index_buffer.size() > max {
        return Some(format!(
            "the vertices or indices exceed a storage binding ({max} bytes)"
        ));
    }
    None
}

/// What [`VisibilityBuffer::new`] reads from the renderer.
pub(crate) struct VisInputs<'a> {
    pub materials: &'a MaterialSet,
    pub geometry: &'a Geometry,
    pub material_gpu: &'a MaterialResources,
    pub layouts: &'a Layouts,
    pub normal_encoding: u32,
}

/// The batches' resolve groups and the variants' modules, before pipelines.
struct Plan {
    resolved: Vec<bool>,
    groups: Vec<ResolveGroup>,
    /// Per pipeline: its variant and module text.
    variants: Vec<(VariantKey, String)>,
    fallback: Vec<String>,
}

/// Sorts the opaque batches into resolve groups and G-buffer draws.
fn plan(inp: &VisInputs<'_>) -> Plan {
    let engine_only = variant::engine_bit("ALPHA_MASK") | variant::engine_bit("HAS_LAYERS");
    let mut p = Plan {
        resolved: Vec::new(),
        groups: Vec::new(),
        variants: Vec::new(),
        fallback: Vec::new(),
    };
    let mut modules: HashMap<VariantKey, Result<usize, String>> = HashMap::new();
    for b in &inp.geometry.batches {
        let m = &inp.materials.materials[b.material];
        let key = VariantKey {
            surface: m.surface,
            lighting: m.lighting,
            features: b.features,
        };
        let pipeline = if b.features & engine_only != 0 {
            Err("alpha test or layers".to_string())
        } else {
            modules
                .entry(key)
                .or_insert_with(|| {
                    let text = resolve_module(inp.materials, key, inp.normal_encoding)?;
                    check("visibility resolve", &text)?;
                    p.variants.push((key, text));
                    Ok(p.variants.len() - 1)
                })
                .clone()
        };
        match pipeline {
            Ok(pipeline) => {
                p.resolved.push(true);
                let found = p
                    .groups
                    .iter()
                    .any(|g| g.material == b.material && g.features == b.features);
                if !found {
                    p.groups.push(ResolveGroup {
                        material: b.material,
                        features: b.features,
                        pipeline,
                    });
                }
            }
            Err(why) => {
                p.resolved.push(false);
                p.fallback.push(format!("`{}` ({why})", m.name));
            }
        }
    }
    p.fallback.dedup();
    p
}

/// The slot records of the resolved batches (the others: no group).
fn slot_records(geometry: &Geometry, p: &Plan) -> Vec<GpuVisSlot> {
    let none = GpuVisSlot {
        first_index: 0,
        base_vertex: 0,
        group: NONE,
        flags: 0,
    };
    let mut slots = vec![none; geometry.slots.len().max(1)];
    for (b, _) in geometry
        .batches
        .iter()
        .zip(&p.resolved)
        .filter(|(_, r)| **r)
    {
        let group = p
            .groups
            .iter()
            .position(|g| g.material == b.material && g.features == b.features)
            .expect("a resolved batch has a group") as u32;
        let clockwise = matches!(b.cull, Cull::BackCw | Cull::NoneCw);
        for slot in b.instances.clone() {
            slots[slot as usize] = GpuVisSlot {
                first_index: b.indices.start,
                base_vertex: b.base_vertex,
                group,
                flags: u32::from(clockwise),
            };
        }
    }
    slots
}

/// Binding `binding`: the whole of `b`.
fn buffer(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: b.as_entire_binding(),
    }
}

impl VisibilityBuffer {
    /// The visibility buffer of the scene, its pipelines created; `None` (with
    /// a warning) where the adapter cannot have one or no draw can be resolved.
    pub fn new(ctx: &GpuContext, inp: &VisInputs<'_>) -> Result<Option<Self>, String> {
        if let Some(why) = unsupported(ctx, inp.geometry) {
            log::warn!("visibility buffer unavailable ({why}): the fat G-buffer is drawn");
            return Ok(None);
        }
        let p = plan(inp);
        if !p.fallback.is_empty() {
            log::info!(
                "visibility buffer: drawn into the G-buffer instead: {}",
                p.fallback.join(", ")
            );
        }
        if p.groups.is_empty() {
            log::warn!(
                "visibility buffer: no draw can be resolved in compute: the fat G-buffer is drawn"
            );
            return Ok(None);
        }
        let device = &ctx.device;
        let layout = resolve_layout(device);
        let mut resolve = Vec::new();
        for (key, text) in &p.variants {
            let surface = &inp.material_gpu.layouts[key.surface];
            let label = format!(
                "visibility resolve ({} + {}, features {:#x})",
                inp.materials.surfaces[key.surface].name,
                inp.materials.lightings[key.lighting].name,
                key.features
            );
            let groups = [
                &inp.layouts.g0,
                &layout,
                surface,
                &inp.material_gpu.params_layout,
            ];
            resolve.push(resolve_pipeline(ctx, &label, groups, text)?);
        }
        let mut raster = HashMap::new();
        for (b, _) in inp
            .geometry
            .batches
            .iter()
            .zip(&p.resolved)
            .filter(|(_, r)| **r)
        {
            if let std::collections::hash_map::Entry::Vacant(e) = raster.entry(b.cull) {
                e.insert(raster_pipeline(ctx, inp.layouts, b.cull)?);
            }
        }
        let slots = slot_records(inp.geometry, &p);
        // one per group, then the clearing dispatch's (list `groups`)
        let lists = p.groups.len() + 1;
        let mut dispatch = vec![0u8; lists * DISPATCH_STRIDE as usize];
        for i in 0..lists {
            let at = i * DISPATCH_STRIDE as usize;
            let words = [i as u32, u32::from(i == p.groups.len()), 0, 0];
            dispatch[at..at + 16].copy_from_slice(bytemuck::cast_slice(&words));
        }
        let classify_layout = classify_layout(device);
        let classify = Classify {
            pipelines: classify_pipelines(ctx, &classify_layout, p.groups.len())?,
            layout: classify_layout,
            counts: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("visibility tile counts"),
                size: lists as u64 * 4,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            args: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("visibility resolve dispatch sizes"),
                size: lists as u64 * 12,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
                mapped_at_creation: false,
            }),
        };
        let init = |label: &str, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let resolved = p.resolved.iter().filter(|r| **r).count();
        log::info!(
            "visibility buffer: {resolved} of {} opaque batches resolved in compute ({} dispatches, {} variants)",
            p.resolved.len(),
            p.groups.len(),
            resolve.len()
        );
        Ok(Some(VisibilityBuffer {
            slots: init(
                "visibility slots",
                bytemuck::cast_slice(&slots),
                wgpu::BufferUsages::STORAGE,
            ),
            dispatch: init(
                "visibility resolve dispatches",
                &dispatch,
                wgpu::BufferUsages::UNIFORM,
            ),
            resolved: p.resolved,
            groups: p.groups,
            resolve,
            raster,
            layout,
            classify,
            targets: None,
        }))
    }

    /// Whether opaque batch `i` is resolved in compute (else it is drawn
    /// into the G-buffer).
    pub fn resolves(&self, i: usize) -> bool {
        self.resolved[i]
    }

    /// Whether some opaque batches are drawn into the G-buffer.
    pub fn has_fallback(&self) -> bool {
        self.resolved.iter().any(|r| !r)
    }

    /// The opaque batches drawn into the G-buffer.
    pub fn fallback_batches(&self) -> usize {
        self.resolved.iter().filter(|r| !**r).count()
    }

    /// The ids and twins for `targets`' size, and the resolve's bind groups
    /// over them and the geometry.
    pub fn ensure_targets(&mut self, ctx: &GpuContext, t: &Targets, geometry: &Geometry) {
        if self
            .targets
            .as_ref()
            .is_some_and(|v| v.size == (t.width, t.height))
        {
            return;
        }
        let device = &ctx.device;
        let make = |label: &str, format, usage| {
            let texture = device.create_texture(&crate::gpu::transfer::texture_2d(
                label,
                (t.width, t.height),
                format,
                usage,
                &[],
            ));
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                ..Default::default()
            });
            Target { texture, view }
        };
        let twin = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
        let ids = make(
            "visibility ids (instance slot, triangle)",
            ID_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let albedo = make(
            "visibility albedo (raw twin)",
            wgpu::TextureFormat::Rgba8Unorm,
            twin,
        );
        let specular = make(
            "visibility specular (raw twin)",
            wgpu::TextureFormat::Rgba8Unorm,
            twin,
        );
        let tiles = t.width.div_ceil(TILE) as u64 * t.height.div_ceil(TILE) as u64;
        let lists = self.groups.len() as u64 + 1;
        let tile_lists = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("visibility tile lists"),
            size: lists * tiles * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let group = |label: &str, light: &wgpu::TextureView| {
            let view = |binding, v| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(v),
            };
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &self.layout,
                entries: &[
                    view(2, &ids.view),
                    buffer(3, &geometry.vertex_buffer),
                    buffer(4, &geometry.index_buffer),
                    buffer(5, &self.slots),
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &self.dispatch,
                            offset: 0,
                            size: wgpu::BufferSize::new(16),
                        }),
                    },
                    view(7, &albedo.view),
                    view(8, &t.normal.view),
                    view(9, &specular.view),
                    view(10, light),
                    buffer(11, &tile_lists),
                    buffer(12, &self.classify.counts),
                ],
            })
        };
        let groups = [
            group("visibility resolve group 1 (emission)", &t.emission.view),
            group(
                "visibility resolve group 1 (specular light)",
                &t.light_specular.view,
            ),
        ];
        let c = &self.classify;
        let classify = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("visibility classification group 0"),
            layout: &c.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&ids.view),
                },
                buffer(1, &self.slots),
                buffer(2, &c.counts),
                buffer(3, &tile_lists),
                buffer(4, &c.args),
            ],
        });
        self.targets = Some(VisTargets {
            size: (t.width, t.height),
            ids,
            albedo,
            specular,
            groups,
            classify,
        });
    }

    /// Records the raster pass (`visibility`) and the resolve (`material
    /// resolve`), then copies the twins into the sRGB targets. `light_start`:
    /// the resolve writes emission + ambient into the emission target (the
    /// compute light pass), else into the specular light buffer. Returns the
    /// draw calls.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (g0, geometry, material_gpu): (&wgpu::BindGroup, &Geometry, &MaterialResources),
        t: &Targets,
        light_start_is_emission: bool,
        (names, timer): (&mut Vec<String>, Option<&GpuTimer>),
    ) -> usize {
        let vt = self.targets.as_ref().expect("visibility targets exist");
        let mut draws = 0;
        let index = names.len() as u32;
        names.push("visibility".into());
        {
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("visibility"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &vt.ids.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(NONE),
                            g: f64::from(NONE),
                            b: 0.0,
                            a: 0.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &t.depth.view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: timer.and_then(|t| t.pass_writes(index)),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_bind_group(0, g0, &[]);
            rp.set_vertex_buffer(0, geometry.vertex_buffer.slice(..));
            rp.set_index_buffer(geometry.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            let mut current = None;
            for (b, _) in geometry
                .batches
                .iter()
                .zip(&self.resolved)
                .filter(|(_, r)| **r)
            {
                if current != Some(b.cull) {
                    rp.set_pipeline(&self.raster[&b.cull]);
                    current = Some(b.cull);
                }
                rp.draw_indexed(b.indices.clone(), b.base_vertex, b.instances.clone());
                draws += 1;
            }
        }
        let index = names.len() as u32;
        names.push("material resolve".into());
        let c = &self.classify;
        encoder.clear_buffer(&c.counts, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("material resolve"),
                timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
            });
            // the tiles of each dispatch, and its size
            pass.set_bind_group(0, &vt.classify, &[]);
            pass.set_pipeline(&c.pipelines[0]);
            pass.dispatch_workgroups(t.width.div_ceil(TILE), t.height.div_ceil(TILE), 1);
            pass.set_pipeline(&c.pipelines[1]);
            pass.dispatch_workgroups((self.groups.len() as u32 + 1).div_ceil(64), 1, 1);
            let group1 = &vt.groups[usize::from(!light_start_is_emission)];
            pass.set_bind_group(0, g0, &[]);
            pass.set_bind_group(3, &material_gpu.params_group, &[]);
            // every group, then the clearing dispatch (with the first's pipeline)
            let clearing = (self.groups.len(), &self.groups[0]);
            for (i, g) in self.groups.iter().enumerate().chain([clearing]) {
                pass.set_pipeline(&self.resolve[g.pipeline]);
                pass.set_bind_group(1, group1, &[(i as u64 * DISPATCH_STRIDE) as u32]);
                pass.set_bind_group(2, material_gpu.group(g.material, g.features), &[]);
                pass.dispatch_workgroups_indirect(&c.args, i as u64 * 12);
            }
        }
        for (twin, target) in [(&vt.albedo, &t.albedo), (&vt.specular, &t.specular)] {
            encoder.copy_texture_to_texture(
                twin.texture.as_image_copy(),
                target.texture.as_image_copy(),
                twin.texture.size(),
            );
        }
        draws
    }
}
