//! The scene's geometry on the GPU: one vertex and one index buffer for every
//! mesh, instances sorted into batches, the instance transforms (now and one
//! frame earlier), and the private vertex ranges of the deformed instances that
//! the skinning pass (`crate::render::skinning`) rewrites per frame.

use super::skinning::Skinning;
use crate::gpu::context::GpuContext;
use crate::render::error::RenderError;
use crate::render::gpu_types::*;
use crate::render::material::{variant, MaterialSet};
use crate::scene::{AlphaMode, Scene};
use glam::{Vec2, Vec3, Vec4};
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
    /// Instances that change shape (skins, morph targets), in scene order: each
    /// draws a private copy of its mesh's vertices, rewritten on the GPU every
    /// frame ([`Geometry::skinning`]).
    pub deformed: Vec<Deformed>,
    /// The vertices one frame earlier where they differ (deformed instances):
    /// the motion pass's previous positions. `None`: as `vertex_buffer`.
    pub prev_vertex_buffer: Option<wgpu::Buffer>,
    /// The GPU deformation of [`Geometry::deformed`] (`None` when there is none).
    pub skinning: Option<Skinning>,
}

/// A deformed instance's private vertices.
#[derive(Debug, Clone)]
pub(crate) struct Deformed {
    /// The scene's instance.
    pub instance: usize,
    /// Its mesh.
    pub mesh: usize,
    /// Its first vertex in the vertex buffer (aligned for a storage binding).
    pub base: u32,
    /// Its vertex count.
    pub vertices: u32,
}

/// The vertex index multiple at which a private range starts, so that its byte
/// offset is a multiple of `alignment` (the device's storage offset alignment).
fn vertex_alignment(alignment: u32) -> usize {
    let stride = std::mem::size_of::<Vertex>();
    let a = alignment.max(1) as usize;
    let gcd = |mut x: usize, mut y: usize| {
        while y != 0 {
            (x, y) = (y, x % y);
        }
        x
    };
    a / gcd(stride, a)
}

/// The feature bits a mesh sets (texture coordinates 1, vertex colours, tangents).
#[cfg(test)]
fn mesh_flags() -> u64 {
    variant::engine_bit("HAS_UV1")
        | variant::engine_bit("HAS_VERTEX_COLOR")
        | variant::engine_bit("HAS_TANGENTS")
}

/// [`mesh_flags`] as a constant (bits 3..5 of the engine flags).
pub(super) const MESH_FLAGS: u64 = 0b111000;

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

/// Every mesh's vertices and indices, one after the other.
struct MeshData {
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
    /// Each mesh's base vertex and index range.
    ranges: Vec<(i32, Range<u32>)>,
}

/// Concatenates the scene's meshes (missing attributes take their defaults);
/// an index past a mesh's vertices is an error.
fn pack_meshes(scene: &Scene) -> Result<MeshData, RenderError> {
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
    Ok(MeshData {
        vertices,
        indices,
        ranges,
    })
}

/// Every instance must name an existing mesh and material.
fn check_instances(scene: &Scene) -> Result<(), RenderError> {
    for inst in &scene.instances {
        if inst.mesh >= scene.meshes.len() || inst.material >= scene.materials.len() {
            return Err(RenderError::Invalid(format!(
                "{}: instance `{}` refers to a missing mesh or material",
                scene.name, inst.name
            )));
        }
    }
    Ok(())
}

/// The face culling of an instance: its material's sidedness, and the winding
/// its transform gives (mirrored: negative determinant).
fn instance_cull(scene: &Scene, inst: &crate::scene::Instance) -> Cull {
    let mirrored = inst.transform.determinant() < 0.0;
    match (scene.materials[inst.material].double_sided, mirrored) {
        (true, false) => Cull::None,
        (true, true) => Cull::NoneCw,
        (false, true) => Cull::BackCw,
        (false, false) => Cull::BackCcw,
    }
}

/// The instances in slot order: sorted so that runs of (cull, material, mesh)
/// become batches, the transparent ones last.
fn slot_order(scene: &Scene) -> Vec<usize> {
    let mut order: Vec<usize> = (0..scene.instances.len()).collect();
    order.sort_by_key(|&i| {
        let inst = &scene.instances[i];
        let blend = scene.materials[inst.material].alpha_mode == AlphaMode::Blend;
        (blend, instance_cull(scene, inst), inst.material, inst.mesh)
    });
    order
}

/// The instances sorted into draws, slot by slot.
#[derive(Default)]
struct Batching {
    gpu_instances: Vec<GpuInstance>,
    batches: Vec<Batch>,
    blend_items: Vec<BlendItem>,
    blend_slots: Vec<usize>,
    deformed: Vec<Deformed>,
}

impl Batching {
    /// Sorts every instance into the draws, in slot order: deformed instances
    /// get a private copy of their mesh's vertices; opaque ones join the
    /// previous batch when it draws the same thing; transparent ones are drawn
    /// one by one.
    fn build(
        scene: &Scene,
        materials: &MaterialSet,
        meshes: &mut MeshData,
        (order, mesh_bounds): (&[usize], &[crate::scene::Aabb]),
        align: usize,
    ) -> Batching {
        let mut b = Batching {
            gpu_instances: Vec::with_capacity(order.len()),
            ..Default::default()
        };
        for (slot, &i) in order.iter().enumerate() {
            let inst = &scene.instances[i];
            b.gpu_instances
                .push(gpu_instance(inst.transform, inst.material as u32));
            let (mut base_vertex, ref idx) = meshes.ranges[inst.mesh];
            let n = scene.meshes[inst.mesh].positions.len();
            if scene.is_deformed(i) && n > 0 {
                base_vertex =
                    b.copy_deformed(&mut meshes.vertices, (i, inst.mesh), base_vertex, n, align);
            }
            let batch = Batch {
                cull: instance_cull(scene, inst),
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
                b.blend_slots.push(slot);
                b.blend_items.push(BlendItem {
                    batch,
                    center: mesh_bounds[inst.mesh].transformed(&inst.transform).center(),
                });
                continue;
            }
            b.add_opaque(batch, slot);
        }
        // in scene order, as `FrameMotion::deformed` lists their poses
        b.deformed.sort_by_key(|d: &Deformed| d.instance);
        b
    }

    /// A private copy of the `n` vertices of a deformed instance's mesh from
    /// `start`, at a storage-aligned offset; returns its base vertex.
    fn copy_deformed(
        &mut self,
        vertices: &mut Vec<Vertex>,
        (instance, mesh): (usize, usize),
        start: i32,
        n: usize,
        align: usize,
    ) -> i32 {
        let start = start as usize;
        vertices.resize(
            vertices.len().next_multiple_of(align),
            bytemuck::Zeroable::zeroed(),
        );
        let base_vertex = vertices.len() as i32;
        vertices.extend_from_within(start..start + n);
        self.deformed.push(Deformed {
            instance,
            mesh,
            base: base_vertex as u32,
            vertices: n as u32,
        });
        base_vertex
    }

    /// An opaque draw: one more instance of the previous batch when it draws
    /// the same thing from the slot before, else a batch of its own.
    fn add_opaque(&mut self, batch: Batch, slot: usize) {
        match self.batches.last_mut() {
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
            _ => self.batches.push(batch),
        }
    }
}

/// The geometry's buffers.
struct GeometryBuffers {
    vertex: wgpu::Buffer,
    index: wgpu::Buffer,
    instance: wgpu::Buffer,
    prev_model: wgpu::Buffer,
    /// The deformed vertices one frame earlier (when there are any).
    prev_vertex: Option<wgpu::Buffer>,
}

/// Uploads the vertices, indices, instances and their previous transforms (a
/// zero instance when there are none), and the previous vertices of the
/// deformed instances.
fn create_buffers(
    ctx: &GpuContext,
    meshes: &MeshData,
    gpu_instances: &mut Vec<GpuInstance>,
    any_deformed: bool,
) -> Result<GeometryBuffers, RenderError> {
    let vertices = &meshes.vertices;
    let prev_models: Vec<[f32; 16]> = gpu_instances.iter().map(|g| g.model).collect();
    if gpu_instances.is_empty() {
        gpu_instances.push(bytemuck::Zeroable::zeroed());
    }
    let prev_models = if prev_models.is_empty() {
        vec![[0.0; 16]]
    } else {
        prev_models
    };
    // the skinning pass writes the deformed instances' ranges (and
    // `Renderer::deformed_vertices` reads them back)
    // (the visibility buffer's material resolve reads vertices and indices as
    // storage: `crate::render::visibility`)
    let deformed_usage = if !any_deformed {
        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE
    } else {
        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC
    };
    let (vertex, index, instance, prev_model) =
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
                    bytemuck::cast_slice(vertices),
                    deformed_usage,
                ),
                init(
                    "deferred indices",
                    bytemuck::cast_slice(&meshes.indices),
                    wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
                ),
                init(
                    "deferred instances",
                    bytemuck::cast_slice(gpu_instances),
                    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                ),
                init(
                    "deferred previous instance transforms",
                    bytemuck::cast_slice(&prev_models),
                    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                ),
            )
        })?;
    let prev_vertex = if !any_deformed {
        None
    } else {
        Some(
            ctx.scoped("deferred renderer: previous vertices", |device| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("deferred previous vertices (motion vectors)"),
                    contents: bytemuck::cast_slice(vertices),
                    usage: deformed_usage,
                })
            })?,
        )
    };
    Ok(GeometryBuffers {
        vertex,
        index,
        instance,
        prev_model,
        prev_vertex,
    })
}

impl Geometry {
    /// Packs the meshes, sorts the instances into batches and uploads them.
    pub fn upload(
        ctx: &GpuContext,
        scene: &Scene,
        materials: &MaterialSet,
    ) -> Result<Geometry, RenderError> {
        let mut meshes = pack_meshes(scene)?;
        check_instances(scene)?;
        let order = slot_order(scene);
        let mesh_bounds: Vec<_> = scene.meshes.iter().map(|m| m.bounds()).collect();
        let align = vertex_alignment(ctx.device.limits().min_storage_buffer_offset_alignment);
        let mut b = Batching::build(scene, materials, &mut meshes, (&order, &mesh_bounds), align);
        let slot_material: Vec<u32> = order
            .iter()
            .map(|&i| scene.instances[i].material as u32)
            .collect();
        let slot_bounds = order
            .iter()
            .map(|&i| mesh_bounds[scene.instances[i].mesh])
            .collect();
        let buffers = create_buffers(ctx, &meshes, &mut b.gpu_instances, !b.deformed.is_empty())?;
        let skinning = match &buffers.prev_vertex {
            Some(prev) => Skinning::new(ctx, scene, &b.deformed, &buffers.vertex, prev)?,
            None => None,
        };
        Ok(Geometry {
            skinning,
            deformed: b.deformed,
            prev_vertex_buffer: buffers.prev_vertex,
            vertex_buffer: buffers.vertex,
            index_buffer: buffers.index,
            instance_buffer: buffers.instance,
            prev_model_buffer: buffers.prev_model,
            batches: b.batches,
            blend_items: b.blend_items,
            vertices: meshes.vertices.len(),
            slots: order,
            slot_material,
            slot_bounds,
            blend_slots: b.blend_slots,
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
    /// World bounds of instance `instance` at `transform` (empty when it has
    /// no drawn primitive).
    pub fn instance_bounds(&self, instance: usize, transform: &glam::Mat4) -> crate::scene::Aabb {
        let mut out = crate::scene::Aabb::EMPTY;
        for (slot, _) in self
            .slots
            .iter()
            .enumerate()
            .filter(|(_, &i)| i == instance)
        {
            let b = self.slot_bounds[slot].transformed(transform);
            if !b.is_empty() {
                out.add(b.min);
                out.add(b.max);
            }
        }
        out
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

#[cfg(test)]
mod tests {
    #[test]
    fn mesh_flag_mask_matches_the_engine_flags() {
        assert_eq!(super::MESH_FLAGS, super::mesh_flags());
    }
}
