//! Uploading a scene: one vertex and one index buffer for every mesh, instances
//! sorted into batches, textures (mipmapped, sRGB or linear as the surface shader
//! declares), and the per-material bind groups (group 2) and lighting parameter
//! arrays (group 3).

use super::gpu_types::*;
use super::material::template::{feature_words, FEATURES_BINDING};
use super::material::{variant, MaterialSet};
use super::pipelines::texture_entry;
use super::renderer::RenderError;
use crate::gpu::bindings;
use crate::gpu::context::{GpuContext, GpuError};
use crate::scene::{AlphaMode, Scene};
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::ops::Range;
use wgpu::util::DeviceExt;

/// Face culling of a geometry pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum Cull {
    /// Double-sided material.
    None,
    /// Double-sided material under a mirroring transform: nothing is culled, but
    /// clockwise triangles are the front faces (so `front_facing` stays right).
    NoneCw,
    /// Back faces culled, counter-clockwise front (glTF).
    BackCcw,
    /// Back faces culled for a mirroring transform (negative determinant).
    BackCw,
}

impl Cull {
    pub fn primitive(self) -> wgpu::PrimitiveState {
        wgpu::PrimitiveState {
            cull_mode: match self {
                Cull::None | Cull::NoneCw => None,
                _ => Some(wgpu::Face::Back),
            },
            front_face: match self {
                Cull::BackCw | Cull::NoneCw => wgpu::FrontFace::Cw,
                _ => wgpu::FrontFace::Ccw,
            },
            ..Default::default()
        }
    }
}

/// An instanced draw of one mesh with one material.
#[derive(Debug, Clone)]
pub(crate) struct Batch {
    pub cull: Cull,
    pub material: usize,
    /// The material's feature bits plus the mesh's (UV1, vertex colour, tangents).
    pub features: u64,
    pub indices: Range<u32>,
    pub base_vertex: i32,
    pub instances: Range<u32>,
}

/// A transparent instance, sorted per frame.
#[derive(Debug, Clone)]
pub(crate) struct BlendItem {
    pub batch: Batch,
    /// World-space centre of the instance's bounds (updated with its transform).
    pub center: Vec3,
}

/// The scene's geometry on the GPU.
///
/// Instances live in the instance buffer in *slot* order (sorted into batches);
/// [`Geometry::slots`] maps a slot back to the scene's instance, so transforms
/// that change per frame (animation) are written in place
/// ([`Geometry::write_transforms`]) without uploading anything else.
pub(crate) struct Geometry {
    pub vertex_buffer: wgpu::Buffer,
    pub index_buffer: wgpu::Buffer,
    pub instance_buffer: wgpu::Buffer,
    /// One model matrix per slot: the instances' transforms one frame earlier,
    /// read by the motion-vector pass (`motion.rs`).
    pub prev_model_buffer: wgpu::Buffer,
    pub batches: Vec<Batch>,
    pub blend_items: Vec<BlendItem>,
    pub vertices: usize,
    /// Slot → index of the scene's instance.
    pub slots: Vec<usize>,
    /// Per slot: the material index and the mesh's local bounds.
    slot_material: Vec<u32>,
    slot_bounds: Vec<crate::scene::Aabb>,
    /// Per blend item: its slot.
    blend_slots: Vec<usize>,
    /// Instances that change shape (skins, morph targets): each draws a private
    /// copy of its mesh's vertices, rewritten every frame
    /// ([`Geometry::write_deformed`]).
    pub deformed: Vec<Deformed>,
    /// The vertices one frame earlier where they differ (deformed instances):
    /// the motion pass's previous positions. `None`: as `vertex_buffer`.
    pub prev_vertex_buffer: Option<wgpu::Buffer>,
}

/// A deformed instance's private vertices.
pub(crate) struct Deformed {
    /// The scene's instance.
    pub instance: usize,
    /// Its first vertex in the vertex buffer.
    pub base: u32,
    /// Its vertices at rest (texture coordinates and colours stay).
    pub rest: Vec<Vertex>,
}

/// The feature bits a mesh sets (texture coordinates 1, vertex colours, tangents).
#[cfg(test)]
fn mesh_flags() -> u64 {
    variant::engine_bit("HAS_UV1")
        | variant::engine_bit("HAS_VERTEX_COLOR")
        | variant::engine_bit("HAS_TANGENTS")
}

/// [`mesh_flags`] as a constant (bits 3..5 of the engine flags).
const MESH_FLAGS: u64 = 0b111000;

fn mesh_features(m: &crate::scene::Mesh) -> u64 {
    let mut f = 0;
    if !m.uvs1.is_empty() {
        f |= variant::engine_bit("HAS_UV1");
    }
    if !m.colors.is_empty() {
        f |= variant::engine_bit("HAS_VERTEX_COLOR");
    }
    if m.tangents.is_some() {
        f |= variant::engine_bit("HAS_TANGENTS");
    }
    f
}

impl Geometry {
    pub fn upload(
        ctx: &GpuContext,
        scene: &Scene,
        materials: &MaterialSet,
    ) -> Result<Geometry, RenderError> {
        let name = &scene.name;
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::with_capacity(scene.meshes.len());
        for m in &scene.meshes {
            let base = vertices.len() as i32;
            let first = indices.len() as u32;
            for i in 0..m.positions.len() {
                let t = m
                    .tangents
                    .as_ref()
                    .and_then(|t| t.get(i).copied())
                    .unwrap_or(Vec4::ZERO);
                vertices.push(Vertex {
                    position: m.positions[i].into(),
                    normal: m.normals.get(i).copied().unwrap_or(Vec3::Y).into(),
                    uv0: m.uvs.get(i).copied().unwrap_or_default().into(),
                    uv1: m.uvs1.get(i).copied().unwrap_or(Vec2::ZERO).into(),
                    tangent: t.into(),
                    color: m.colors.get(i).copied().unwrap_or(Vec4::ONE).into(),
                });
            }
            if let Some(&bad) = m.indices.iter().find(|&&i| i as usize >= m.positions.len()) {
                return Err(RenderError::Invalid(format!(
                    "{name}: mesh `{}` has index {bad} >= {} vertices",
                    m.name,
                    m.positions.len()
                )));
            }
            indices.extend_from_slice(&m.indices);
            ranges.push((base, first..indices.len() as u32));
        }
        for inst in &scene.instances {
            if inst.mesh >= scene.meshes.len() || inst.material >= scene.materials.len() {
                return Err(RenderError::Invalid(format!(
                    "{name}: instance `{}` refers to a missing mesh or material",
                    inst.name
                )));
            }
        }
        let cull_of = |inst: &crate::scene::Instance| -> Cull {
            let mirrored = inst.transform.determinant() < 0.0;
            match (scene.materials[inst.material].double_sided, mirrored) {
                (true, false) => Cull::None,
                (true, true) => Cull::NoneCw,
                (false, true) => Cull::BackCw,
                (false, false) => Cull::BackCcw,
            }
        };
        // Sorted so that runs of (cull, material, mesh) become batches.
        let mut order: Vec<usize> = (0..scene.instances.len()).collect();
        order.sort_by_key(|&i| {
            let inst = &scene.instances[i];
            let blend = scene.materials[inst.material].alpha_mode == AlphaMode::Blend;
            (blend, cull_of(inst), inst.material, inst.mesh)
        });
        let mut gpu_instances = Vec::with_capacity(order.len());
        let mut batches: Vec<Batch> = Vec::new();
        let mut blend_items = Vec::new();
        let mut blend_slots = Vec::new();
        let mesh_bounds: Vec<_> = scene.meshes.iter().map(|m| m.bounds()).collect();
        let mut deformed = Vec::new();
        for (slot, &i) in order.iter().enumerate() {
            let inst = &scene.instances[i];
            let model = inst.transform;
            gpu_instances.push(gpu_instance(model, inst.material as u32));
            let (mut base_vertex, ref idx) = ranges[inst.mesh];
            if scene.is_deformed(i) {
                // a private copy of the mesh's vertices
                let n = scene.meshes[inst.mesh].positions.len();
                let rest = vertices[base_vertex as usize..base_vertex as usize + n].to_vec();
                base_vertex = vertices.len() as i32;
                vertices.extend_from_slice(&rest);
                deformed.push(Deformed {
                    instance: i,
                    base: base_vertex as u32,
                    rest,
                });
            }
            let batch = Batch {
                cull: cull_of(inst),
                material: inst.material,
                features: materials.materials[inst.material].features
                    | mesh_features(&scene.meshes[inst.mesh]),
                indices: idx.clone(),
                base_vertex,
                instances: slot as u32..slot as u32 + 1,
            };
            if batch.indices.is_empty() {
                continue;
            }
            if scene.materials[inst.material].alpha_mode == AlphaMode::Blend {
                blend_slots.push(slot);
                blend_items.push(BlendItem {
                    batch,
                    center: mesh_bounds[inst.mesh].transformed(&model).center(),
                });
                continue;
            }
            match batches.last_mut() {
                Some(last)
                    if last.cull == batch.cull
                        && last.material == batch.material
                        && last.features == batch.features
                        && last.indices == batch.indices
                        && last.base_vertex == batch.base_vertex
                        && last.instances.end == slot as u32 =>
                {
                    last.instances.end += 1;
                }
                _ => batches.push(batch),
            }
        }
        let slot_material: Vec<u32> = order
            .iter()
            .map(|&i| scene.instances[i].material as u32)
            .collect();
        let slot_bounds = order
            .iter()
            .map(|&i| mesh_bounds[scene.instances[i].mesh])
            .collect();
        let prev_models: Vec<[f32; 16]> = gpu_instances.iter().map(|g| g.model).collect();
        if gpu_instances.is_empty() {
            gpu_instances.push(bytemuck::Zeroable::zeroed());
        }
        let prev_models = if prev_models.is_empty() {
            vec![[0.0; 16]]
        } else {
            prev_models
        };
        let (vertex_buffer, index_buffer, instance_buffer, prev_model_buffer) =
            ctx.scoped("deferred renderer: geometry upload", |device| {
                let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(label),
                        contents,
                        usage,
                    })
                };
                (
                    init(
                        "deferred vertices",
                        bytemuck::cast_slice(&vertices),
                        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    ),
                    init(
                        "deferred indices",
                        bytemuck::cast_slice(&indices),
                        wgpu::BufferUsages::INDEX,
                    ),
                    init(
                        "deferred instances",
                        bytemuck::cast_slice(&gpu_instances),
                        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    ),
                    init(
                        "deferred previous instance transforms",
                        bytemuck::cast_slice(&prev_models),
                        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    ),
                )
            })?;
        let prev_vertex_buffer = if deformed.is_empty() {
            None
        } else {
            Some(
                ctx.scoped("deferred renderer: previous vertices", |device| {
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("deferred previous vertices (motion vectors)"),
                        contents: bytemuck::cast_slice(&vertices),
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    })
                })?,
            )
        };
        Ok(Geometry {
            deformed,
            prev_vertex_buffer,
            vertex_buffer,
            index_buffer,
            instance_buffer,
            prev_model_buffer,
            batches,
            blend_items,
            vertices: vertices.len(),
            slots: order,
            slot_material,
            slot_bounds,
            blend_slots,
        })
    }

    /// Writes the instances' world transforms (`transforms[i]` for the scene's
    /// instance `i`) now and one frame earlier; updates the transparent
    /// instances' sort centres and returns the world bounds of the geometry.
    /// Face culling was chosen from the rest pose: an animation that mirrors an
    /// instance (negative determinant) keeps the rest pose's winding.
    pub fn write_transforms(
        &mut self,
        ctx: &GpuContext,
        transforms: &[glam::Mat4],
        prev: &[glam::Mat4],
    ) -> crate::scene::Aabb {
        let mut bounds = crate::scene::Aabb::EMPTY;
        let gpu: Vec<GpuInstance> = self
            .slots
            .iter()
            .enumerate()
            .map(|(slot, &i)| {
                let t = self.slot_bounds[slot].transformed(&transforms[i]);
                if !t.is_empty() {
                    bounds.add(t.min);
                    bounds.add(t.max);
                }
                gpu_instance(transforms[i], self.slot_material[slot])
            })
            .collect();
        let prev: Vec<[f32; 16]> = self.slots.iter().map(|&i| mat_array(prev[i])).collect();
        for (item, &slot) in self.blend_items.iter_mut().zip(&self.blend_slots) {
            item.center = self.slot_bounds[slot]
                .transformed(&transforms[self.slots[slot]])
                .center();
        }
        if !gpu.is_empty() {
            ctx.queue
                .write_buffer(&self.instance_buffer, 0, bytemuck::cast_slice(&gpu));
            ctx.queue
                .write_buffer(&self.prev_model_buffer, 0, bytemuck::cast_slice(&prev));
        }
        bounds
    }
}

impl Geometry {
    /// Writes the vertices of the deformed instances now (`now`: per entry of
    /// [`Geometry::deformed`], object-space positions, normals and tangents) and
    /// one frame earlier (`prev`, positions for the motion vectors).
    pub fn write_deformed(
        &self,
        ctx: &GpuContext,
        now: &[crate::scene::PosedMesh],
        prev: &[crate::scene::PosedMesh],
    ) {
        let write = |buffer: &wgpu::Buffer, d: &Deformed, m: &crate::scene::PosedMesh| {
            let v: Vec<Vertex> = d
                .rest
                .iter()
                .enumerate()
                .map(|(k, r)| Vertex {
                    position: m.positions.get(k).copied().unwrap_or_default().into(),
                    normal: m.normals.get(k).copied().unwrap_or(Vec3::Y).into(),
                    tangent: m
                        .tangents
                        .as_ref()
                        .and_then(|t| t.get(k).copied())
                        .map_or(r.tangent, Into::into),
                    ..*r
                })
                .collect();
            let offset = u64::from(d.base) * std::mem::size_of::<Vertex>() as u64;
            ctx.queue
                .write_buffer(buffer, offset, bytemuck::cast_slice(&v));
        };
        for (d, m) in self.deformed.iter().zip(now) {
            write(&self.vertex_buffer, d, m);
        }
        if let Some(pb) = &self.prev_vertex_buffer {
            for (d, m) in self.deformed.iter().zip(prev) {
                write(pb, d, m);
            }
        }
    }

    /// The opaque draws, one instance each, of the instances whose transform
    /// differs between `transforms` and `prev` (scene order), and of the deformed
    /// ones: what the motion pass draws again.
    pub fn moving(&self, transforms: &[glam::Mat4], prev: &[glam::Mat4]) -> Vec<Batch> {
        let mut out = Vec::new();
        for b in &self.batches {
            for slot in b.instances.clone() {
                let i = self.slots[slot as usize];
                if transforms[i] != prev[i] || self.deformed.iter().any(|d| d.instance == i) {
                    out.push(Batch {
                        instances: slot..slot + 1,
                        ..b.clone()
                    });
                }
            }
        }
        out
    }
}

/// The GPU record of an instance with world transform `model`.
fn gpu_instance(model: glam::Mat4, material: u32) -> GpuInstance {
    GpuInstance {
        model: mat_array(model),
        normal: mat_array(model.inverse().transpose()),
        material,
        _pad: [0; 3],
    }
}

/// A box-filtered mip chain of RGBA8 data (level 0 first). With `srgb` the
/// colour channels are averaged in linear light (averaging the encoded values
/// would darken every level); alpha is always linear.
fn mip_chain(
    width: u32,
    height: u32,
    data: &[u8],
    levels: u32,
    srgb: bool,
) -> Vec<(u32, u32, Vec<u8>)> {
    let lut = crate::io::srgb::decode_lut_u8();
    let mut out = vec![(width, height, data.to_vec())];
    for _ in 1..levels {
        let (pw, ph, prev) = out.last().expect("level 0 exists");
        let (w, h) = ((pw / 2).max(1), (ph / 2).max(1));
        let mut next = vec![0u8; (w * h * 4) as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..4 {
                    let texel = |dx: u32, dy: u32| {
                        let sx = (x * 2 + dx).min(pw - 1);
                        let sy = (y * 2 + dy).min(ph - 1);
                        prev[((sy * pw + sx) * 4 + c) as usize]
                    };
                    let quad = [texel(0, 0), texel(1, 0), texel(0, 1), texel(1, 1)];
                    next[((y * w + x) * 4 + c) as usize] = if srgb && c < 3 {
                        let mean = quad.iter().map(|&v| lut[v as usize]).sum::<f32>() / 4.0;
                        crate::io::srgb::encode_u8(mean)
                    } else {
                        ((quad.iter().map(|&v| u32::from(v)).sum::<u32>() + 2) / 4) as u8
                    };
                }
            }
        }
        out.push((w, h, next));
    }
    out
}

/// Group 2 (per material) and group 3 (lighting parameters) resources.
pub(crate) struct MaterialResources {
    /// One layout per surface shader.
    pub layouts: Vec<wgpu::BindGroupLayout>,
    /// One bind group per (material, mesh flags) drawn; see [`MaterialResources::group`].
    groups: HashMap<(usize, u64), wgpu::BindGroup>,
    pub params_layout: wgpu::BindGroupLayout,
    pub params_group: wgpu::BindGroup,
    /// GPU textures created (each image once per colour space).
    pub textures: usize,
}

/// A uniform buffer read by the fragment stage.
fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    bindings::uniform_entry(binding, wgpu::ShaderStages::FRAGMENT)
}

impl MaterialResources {
    /// The bind group of a batch of `material` with feature bits `features`.
    pub fn group(&self, material: usize, features: u64) -> &wgpu::BindGroup {
        &self.groups[&(material, features & MESH_FLAGS)]
    }

    pub fn upload(
        ctx: &GpuContext,
        scene: &Scene,
        set: &MaterialSet,
        geometry: &Geometry,
        mipmaps: bool,
        white: &wgpu::TextureView,
    ) -> Result<MaterialResources, RenderError> {
        let device = &ctx.device;
        let name = &scene.name;
        let max_dim = device.limits().max_texture_dimension_2d;
        for t in &scene.textures {
            if t.width == 0 || t.height == 0 || t.width > max_dim || t.height > max_dim {
                return Err(RenderError::Invalid(format!(
                    "{name}: texture `{}` is {}x{}; this device allows 1..{max_dim} px",
                    t.name, t.width, t.height
                )));
            }
            if t.rgba8.len() != (t.width * t.height * 4) as usize {
                return Err(RenderError::Invalid(format!(
                    "{name}: texture `{}` has {} bytes for {}x{} RGBA8",
                    t.name,
                    t.rgba8.len(),
                    t.width,
                    t.height
                )));
            }
        }
        let layouts: Vec<wgpu::BindGroupLayout> = set
            .surfaces
            .iter()
            .map(|s| {
                let mut entries = Vec::new();
                if let Some(b) = s.shader.params_binding {
                    entries.push(uniform_entry(b));
                }
                let filterable = wgpu::TextureSampleType::Float { filterable: true };
                for t in &s.shader.textures {
                    entries.push(texture_entry(t.binding, filterable));
                }
                let fragment = wgpu::ShaderStages::FRAGMENT;
                for sampler in &s.shader.samplers {
                    let ty = wgpu::SamplerBindingType::Filtering;
                    entries.push(bindings::sampler_entry(sampler.binding, fragment, ty));
                }
                entries.push(uniform_entry(FEATURES_BINDING));
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&format!("deferred group 2 (surface {})", s.name)),
                    entries: &entries,
                })
            })
            .collect();
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("deferred material sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let mut views: HashMap<(usize, bool), wgpu::TextureView> = HashMap::new();
        let mut texture_view = |index: usize, srgb: bool| -> Result<wgpu::TextureView, GpuError> {
            if let Some(v) = views.get(&(index, srgb)) {
                return Ok(v.clone());
            }
            let t = &scene.textures[index];
            let levels = if mipmaps {
                32 - t.width.max(t.height).leading_zeros()
            } else {
                1
            };
            let format = if srgb {
                wgpu::TextureFormat::Rgba8UnormSrgb
            } else {
                wgpu::TextureFormat::Rgba8Unorm
            };
            let label = format!(
                "deferred texture {} ({})",
                t.name,
                if srgb { "sRGB" } else { "linear" }
            );
            let view = ctx.scoped(&label, |device| {
                let texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(&label),
                    size: wgpu::Extent3d {
                        width: t.width,
                        height: t.height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: levels,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                });
                for (level, (w, h, data)) in mip_chain(t.width, t.height, &t.rgba8, levels, srgb)
                    .iter()
                    .enumerate()
                {
                    ctx.queue.write_texture(
                        wgpu::TexelCopyTextureInfo {
                            texture: &texture,
                            mip_level: level as u32,
                            origin: wgpu::Origin3d::ZERO,
                            aspect: wgpu::TextureAspect::All,
                        },
                        data,
                        wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(w * 4),
                            rows_per_image: Some(*h),
                        },
                        wgpu::Extent3d {
                            width: *w,
                            height: *h,
                            depth_or_array_layers: 1,
                        },
                    );
                }
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&label),
                    ..Default::default()
                })
            })?;
            views.insert((index, srgb), view.clone());
            Ok(view)
        };
        // One bind group per (material, mesh flags) pair drawn: the branching
        // mode reads the exact feature bits (material's and mesh's) from it.
        let mut pairs: Vec<(usize, u64)> = geometry
            .batches
            .iter()
            .chain(geometry.blend_items.iter().map(|b| &b.batch))
            .map(|b| (b.material, b.features & MESH_FLAGS))
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut groups = HashMap::new();
        for (mi, mesh_bits) in pairs {
            let m = &set.materials[mi];
            let s = &set.surfaces[m.surface];
            let label = format!("deferred material {} (mesh flags {mesh_bits:#x})", m.name);
            let mut slot_views = Vec::with_capacity(m.textures.len());
            for (slot, tex) in m.textures.iter().enumerate() {
                slot_views.push(match tex {
                    Some(i) => texture_view(*i, s.shader.textures[slot].srgb)?,
                    None => white.clone(),
                });
            }
            let params = (!m.surface_params.is_empty()).then(|| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("{label} parameters")),
                    contents: &m.surface_params,
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            });
            let feature_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} feature bits")),
                contents: bytemuck::cast_slice(&feature_words(m.features | mesh_bits)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let mut entries = Vec::new();
            if let (Some(b), Some(buf)) = (s.shader.params_binding, &params) {
                entries.push(wgpu::BindGroupEntry {
                    binding: b,
                    resource: buf.as_entire_binding(),
                });
            }
            for (t, v) in s.shader.textures.iter().zip(&slot_views) {
                entries.push(wgpu::BindGroupEntry {
                    binding: t.binding,
                    resource: wgpu::BindingResource::TextureView(v),
                });
            }
            for sampler_var in &s.shader.samplers {
                entries.push(wgpu::BindGroupEntry {
                    binding: sampler_var.binding,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                });
            }
            entries.push(wgpu::BindGroupEntry {
                binding: FEATURES_BINDING,
                resource: feature_buffer.as_entire_binding(),
            });
            let layout = &layouts[m.surface];
            let group = ctx.scoped(&label, |device| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&label),
                    layout,
                    entries: &entries,
                })
            })?;
            groups.insert((mi, mesh_bits), group);
        }
        // Group 3: per lighting model with parameters, an array over all material
        // ids (entries of other models stay zero).
        let mut p_entries = Vec::new();
        let mut p_buffers = Vec::new();
        for (k, l) in set.lightings.iter().enumerate() {
            if !l.takes_params() {
                continue;
            }
            let stride = l.params_stride().max(4);
            let mut bytes = vec![0u8; stride * set.materials.len().max(1)];
            for (i, m) in set.materials.iter().enumerate() {
                if m.lighting == k {
                    bytes[i * stride..i * stride + m.lighting_params.len()]
                        .copy_from_slice(&m.lighting_params);
                }
            }
            p_entries.push(bindings::storage_entry(
                k as u32,
                wgpu::ShaderStages::FRAGMENT,
            ));
            p_buffers.push((
                k as u32,
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("deferred lighting parameters ({})", l.name)),
                    contents: &bytes,
                    usage: wgpu::BufferUsages::STORAGE,
                }),
            ));
        }
        let params_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred group 3 (lighting parameters)"),
            entries: &p_entries,
        });
        let params_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred group 3 (lighting parameters)"),
            layout: &params_layout,
            entries: &p_buffers
                .iter()
                .map(|(b, buf)| wgpu::BindGroupEntry {
                    binding: *b,
                    resource: buf.as_entire_binding(),
                })
                .collect::<Vec<_>>(),
        });
        Ok(MaterialResources {
            layouts,
            groups,
            params_layout,
            params_group,
            textures: views.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn mesh_flag_mask_matches_the_engine_flags() {
        assert_eq!(super::MESH_FLAGS, super::mesh_flags());
    }

    #[test]
    fn srgb_mips_average_in_linear_light() {
        // a black/white checker: the linear mean is 0.5, sRGB-encoded 188
        let data: Vec<u8> = (0..4)
            .flat_map(|i| {
                if i == 0 || i == 3 {
                    [255u8; 4]
                } else {
                    [0, 0, 0, 255]
                }
            })
            .collect();
        let srgb = super::mip_chain(2, 2, &data, 2, true);
        assert_eq!(srgb[1].2, vec![188, 188, 188, 255]);
        let linear = super::mip_chain(2, 2, &data, 2, false);
        assert_eq!(linear[1].2, vec![128, 128, 128, 255]);
    }
}
