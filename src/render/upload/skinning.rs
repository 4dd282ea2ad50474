//! GPU skinning and morph targets: the deformed instances' vertices are computed
//! on the GPU every frame from data uploaded once.
//!
//! Uploaded with the scene (one storage buffer for all deformed meshes, each
//! mesh once however many instances draw it): the rest positions, normals and
//! tangents, the joint indices and weights (4 or 8 per vertex), the morph target
//! displacements. Written per frame (one `write_buffer` for all instances): the
//! joint matrices now and one frame earlier (for the motion vectors) and the morph
//! weights now and one frame earlier.
//!
//! A compute pass (`shaders/skinning.wgsl`, one invocation per vertex, no
//! barriers), encoded first in the frame, writes each deformed instance's
//! vertices into its private range of the vertex buffer (`Geometry::deformed`)
//! and its previous positions into the same range of `prev_vertex_buffer`; the
//! shadow, geometry and motion passes then draw them as any other vertices.
//!
//! The CPU reference is `Pose::deformed_mesh` (src/scene/animation/skin.rs);
//! tests/gpu_skinning.rs compares the two. Limits: [`crate::scene::MAX_JOINTS`]
//! joints per skin and [`crate::scene::MAX_MORPH_TARGETS`] targets per mesh
//! (refused by the scene loader), and a deformed mesh's data must fit one storage
//! binding of the device (`max_storage_buffer_binding_size`, 128 MiB by default:
//! about 1.8 M vertices per deformed instance), else the renderer refuses the
//! scene.

use super::{Deformed, Geometry};
use crate::gpu::bindings;
use crate::gpu::context::{GpuContext, GpuTimer};
use crate::render::error::RenderError;
use crate::render::gpu_types::Vertex;
use crate::scene::{InstancePose, Scene};
use bytemuck::{Pod, Zeroable};
use std::collections::HashMap;
use wgpu::util::DeviceExt;

const SHADER: &str = include_str!("../../../shaders/render/skinning.wgsl");
const WORKGROUP: u32 = 64;
const COMPUTE: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;
/// `targets` entry of an attribute a morph target does not displace.
const NONE: u32 = u32::MAX;

/// `SkinInfo` of skinning.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuSkinInfo {
    vertices: u32,
    sets: u32,
    joints: u32,
    targets: u32,
    mesh_base: u32,
    influences: u32,
    target_base: u32,
    pose_base: u32,
    flat: u32,
    row: u32,
    _pad: [u32; 2],
}

/// One deformed instance's dispatch.
struct SkinnedInstance {
    /// Joint matrices and morph targets it takes per frame.
    joints: usize,
    targets: usize,
    /// First vec4 of its pose in the pose buffer.
    pose_base: usize,
    group: wgpu::BindGroup,
    workgroups: (u32, u32),
}

/// The GPU deformation of a scene's skinned and morphed instances.
pub(crate) struct Skinning {
    pipeline: wgpu::ComputePipeline,
    pose_buffer: wgpu::Buffer,
    instances: Vec<SkinnedInstance>,
    /// vec4s of the pose buffer.
    pose_len: usize,
    /// The pose last written (a frame with the same pose skips the pass: the
    /// vertices already hold it).
    written: Vec<[f32; 4]>,
    /// Whether the vertices hold a deformation (so a still frame restores rest).
    deformed: bool,
    /// Whether the next frame runs the pass (a pose was written).
    pending: bool,
}

/// The static data of the deformed meshes (vec4s) and their morph target table.
#[derive(Default)]
struct MeshData {
    data: Vec<[f32; 4]>,
    targets: Vec<[u32; 4]>,
    /// Per mesh: (mesh_base, influences, target_base, sets).
    placed: HashMap<usize, [u32; 4]>,
}

impl MeshData {
    fn add(&mut self, mesh: &crate::scene::Mesh, index: usize) -> [u32; 4] {
        if let Some(p) = self.placed.get(&index) {
            return *p;
        }
        let n = mesh.positions.len();
        let mesh_base = self.data.len() as u32;
        for v in 0..n {
            let p = mesh.positions[v];
            let nm = mesh.normals.get(v).copied().unwrap_or(glam::Vec3::Y);
            let t = mesh
                .tangents
                .as_ref()
                .and_then(|t| t.get(v).copied())
                .unwrap_or(glam::Vec4::ZERO);
            self.data.push([p.x, p.y, p.z, 0.0]);
            self.data.push([nm.x, nm.y, nm.z, 0.0]);
            self.data.push(t.to_array());
        }
        let influences = self.data.len() as u32;
        let sets: u32 = if !mesh.is_skinned() {
            0
        } else if mesh.joints1.is_empty() {
            1
        } else {
            2
        };
        for v in 0..n {
            let pairs = [
                (&mesh.joints, &mesh.weights),
                (&mesh.joints1, &mesh.weights1),
            ];
            for (joints, weights) in pairs.into_iter().take(sets as usize) {
                let j = joints.get(v).copied().unwrap_or_default();
                self.data.push(j.map(f32::from));
                let w = weights.get(v).copied().unwrap_or(glam::Vec4::ZERO);
                self.data.push(w.to_array());
            }
        }
        let target_base = self.targets.len() as u32;
        for t in &mesh.morph_targets {
            let mut entry = [NONE; 4];
            let tangents: &[glam::Vec3] = if mesh.tangents.is_some() {
                &t.tangents
            } else {
                &[]
            };
            for (slot, deltas) in [&t.positions[..], &t.normals[..], tangents]
                .into_iter()
                .enumerate()
            {
                if deltas.len() == n && n > 0 {
                    entry[slot] = self.data.len() as u32;
                    self.data
                        .extend(deltas.iter().map(|d| [d.x, d.y, d.z, 0.0]));
                }
            }
            self.targets.push(entry);
        }
        let placed = [mesh_base, influences, target_base, sets];
        self.placed.insert(index, placed);
        placed
    }
}

/// The private vertex range of `d` in `buffer`.
fn vertex_range<'b>(buffer: &'b wgpu::Buffer, d: &Deformed) -> wgpu::BindingResource<'b> {
    let stride = std::mem::size_of::<Vertex>() as u64;
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: u64::from(d.base) * stride,
        size: wgpu::BufferSize::new(u64::from(d.vertices.max(1)) * stride),
    })
}

/// Refuses the skinning shader early (an internal error) when naga rejects it.
fn check_shader() -> Result<(), RenderError> {
    crate::render::wgsl_check::check("skinning", SHADER).map_err(|message| {
        RenderError::from(crate::gpu::context::GpuError::Internal {
            what: "skinning".into(),
            message,
        })
    })
}

/// The deformation's layout on the GPU: each instance's info and workgroups,
/// and the pose buffer's length in vec4s.
struct DispatchPlan {
    infos: Vec<(GpuSkinInfo, (u32, u32))>,
    pose_len: usize,
}

/// Places every deformed instance's mesh in `data` (each mesh once) and plans
/// its dispatch and its place in the pose buffer; everything must fit one
/// storage binding of `limit` bytes (the padding of empty tables added).
fn plan_dispatches(
    scene: &Scene,
    deformed: &[Deformed],
    data: &mut MeshData,
    limit: u64,
) -> Result<DispatchPlan, RenderError> {
    let too_big = |what: &str, bytes: u64| {
        RenderError::Invalid(format!(
            "{}: {what} needs {bytes} bytes of GPU storage, this device binds at most {limit}",
            scene.name
        ))
    };
    let mut infos = Vec::with_capacity(deformed.len());
    let mut pose_len = 0usize;
    for d in deformed {
        let inst = &scene.instances[d.instance];
        let mesh = &scene.meshes[d.mesh];
        let [mesh_base, influences, target_base, sets] = data.add(mesh, d.mesh);
        let joints = inst
            .skin
            .and_then(|s| scene.skins.get(s))
            .map_or(0, |s| s.joints.len().min(s.inverse_bind_matrices.len()));
        let targets = mesh.morph_targets.len();
        let groups = d.vertices.div_ceil(WORKGROUP);
        let x = groups.clamp(1, 65535);
        let workgroups = (x, groups.div_ceil(x).max(1));
        let bytes = u64::from(d.vertices) * std::mem::size_of::<Vertex>() as u64;
        if bytes > limit {
            return Err(too_big(&format!("deformed mesh `{}`", mesh.name), bytes));
        }
        infos.push((
            GpuSkinInfo {
                vertices: d.vertices,
                sets,
                joints: joints as u32,
                targets: targets as u32,
                mesh_base,
                influences,
                target_base,
                pose_base: pose_len as u32,
                flat: u32::from(mesh.flat),
                row: x * WORKGROUP,
                _pad: [0; 2],
            },
            workgroups,
        ));
        pose_len += 1 + 8 * joints + (2 * targets).div_ceil(4);
    }
    let data_bytes = (data.data.len() * 16) as u64;
    if data_bytes > limit {
        return Err(too_big("the deformed meshes", data_bytes));
    }
    if data.data.is_empty() {
        data.data.push([0.0; 4]);
    }
    if data.targets.is_empty() {
        data.targets.push([NONE; 4]);
    }
    Ok(DispatchPlan { infos, pose_len })
}

/// The pipeline, its group layout and the buffers every instance shares.
struct SharedGpu {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    mesh_buffer: wgpu::Buffer,
    target_buffer: wgpu::Buffer,
    pose_buffer: wgpu::Buffer,
}

/// Creates the skinning pipeline and uploads the meshes' data, the morph
/// target table and a zero pose buffer of `pose_len` vec4s.
fn create_shared(
    ctx: &GpuContext,
    data: &MeshData,
    pose_len: usize,
) -> Result<SharedGpu, RenderError> {
    Ok(ctx.scoped("skinning", |device| {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("skinning group 0"),
            entries: &[
                bindings::uniform_entry(0, COMPUTE),
                bindings::storage_entry(1, COMPUTE),
                bindings::storage_entry(2, COMPUTE),
                bindings::storage_entry(3, COMPUTE),
                bindings::storage_rw_entry(4, COMPUTE),
                bindings::storage_rw_entry(5, COMPUTE),
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("skinning"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("skinning"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("skinning"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("fx_cs_skin"),
            compilation_options: Default::default(),
            cache: ctx.pipeline_cache.as_ref(),
        });
        let init = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        SharedGpu {
            mesh_buffer: init(
                "skinning rest vertices, influences and morph targets",
                bytemuck::cast_slice(&data.data),
            ),
            target_buffer: init(
                "skinning morph target table",
                bytemuck::cast_slice(&data.targets),
            ),
            pose_buffer: init(
                "skinning joint matrices and morph weights (per frame)",
                bytemuck::cast_slice(&vec![[0f32; 4]; pose_len]),
            ),
            pipeline,
            layout,
        }
    })?)
}

impl SharedGpu {
    /// The group of one deformed instance: its info, the shared buffers, and
    /// its private ranges of the vertices now and one frame earlier.
    fn instance_group(
        &self,
        ctx: &GpuContext,
        label: &str,
        (d, info): (&Deformed, &GpuSkinInfo),
        (vertices, prev_vertices): (&wgpu::Buffer, &wgpu::Buffer),
    ) -> Result<wgpu::BindGroup, RenderError> {
        Ok(ctx.scoped(label, |device| {
            let info_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} info")),
                contents: bytemuck::bytes_of(info),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: info_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: self.mesh_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: self.target_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: self.pose_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: vertex_range(vertices, d),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: vertex_range(prev_vertices, d),
                    },
                ],
            })
        })?)
    }
}

impl Skinning {
    /// The deformation of `deformed` (their private ranges in `vertices` and
    /// `prev_vertices`); `None` when there is none.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        deformed: &[Deformed],
        vertices: &wgpu::Buffer,
        prev_vertices: &wgpu::Buffer,
    ) -> Result<Option<Skinning>, RenderError> {
        if deformed.is_empty() {
            return Ok(None);
        }
        check_shader()?;
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let mut data = MeshData::default();
        let plan = plan_dispatches(scene, deformed, &mut data, limit)?;
        let shared = create_shared(ctx, &data, plan.pose_len)?;
        let mut instances = Vec::with_capacity(deformed.len());
        for (d, (info, workgroups)) in deformed.iter().zip(plan.infos) {
            let label = format!("skinning `{}`", scene.instances[d.instance].name);
            let group =
                shared.instance_group(ctx, &label, (d, &info), (vertices, prev_vertices))?;
            instances.push(SkinnedInstance {
                joints: info.joints as usize,
                targets: info.targets as usize,
                pose_base: info.pose_base as usize,
                group,
                workgroups,
            });
        }
        Ok(Some(Skinning {
            pipeline: shared.pipeline,
            pose_buffer: shared.pose_buffer,
            instances,
            pose_len: plan.pose_len,
            written: Vec::new(),
            deformed: false,
            pending: false,
        }))
    }

    /// Writes the poses of the deformed instances (in `Geometry::deformed`
    /// order) now and one frame earlier: their joint matrices (all of the
    /// instance's skin, or none: not skinned) and morph weights (missing ones are
    /// 0, extra ones ignored). The next frame deforms the vertices.
    pub fn write_pose(
        &mut self,
        ctx: &GpuContext,
        now: &[InstancePose],
        prev: &[InstancePose],
    ) -> Result<(), String> {
        let mut pose = vec![[0f32; 4]; self.pose_len];
        for (i, s) in self.instances.iter().enumerate() {
            let frames = [&now[i], &prev[i]];
            for (f, p) in frames.iter().enumerate() {
                let j = p.joint_matrices.len();
                if j != 0 && j != s.joints {
                    return Err(format!(
                        "{j} joint matrices for a skin of {} joints",
                        s.joints
                    ));
                }
                pose[s.pose_base][f] = if j == 0 { 0.0 } else { 1.0 };
                for (k, m) in p.joint_matrices.iter().enumerate() {
                    let at = s.pose_base + 1 + 4 * (f * s.joints + k);
                    for c in 0..4 {
                        pose[at + c] = m.col(c).to_array();
                    }
                }
                for (k, &w) in p.morph_weights.iter().take(s.targets).enumerate() {
                    let at = f * s.targets + k;
                    pose[s.pose_base + 1 + 8 * s.joints + at / 4][at % 4] = w;
                }
            }
        }
        if self.deformed && pose == self.written {
            self.pending = false;
            return Ok(());
        }
        ctx.queue
            .write_buffer(&self.pose_buffer, 0, bytemuck::cast_slice(&pose));
        self.written = pose;
        self.deformed = true;
        self.pending = true;
        Ok(())
    }

    /// A frame without poses: the vertices at rest (the pass runs once more
    /// if the previous frame deformed them).
    pub fn rest(&mut self, ctx: &GpuContext) {
        self.pending = self.deformed;
        if self.deformed {
            let pose = vec![[0f32; 4]; self.pose_len];
            ctx.queue
                .write_buffer(&self.pose_buffer, 0, bytemuck::cast_slice(&pose));
            self.written.clear();
            self.deformed = false;
        }
    }

    /// Encodes the pass when a pose was written (named "skinning" in `names`,
    /// timed with `timer`).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        names: &mut Vec<String>,
        timer: Option<&GpuTimer>,
    ) {
        if !self.pending {
            return;
        }
        let index = names.len() as u32;
        names.push("skinning".into());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("skinning and morph targets"),
            timestamp_writes: timer.and_then(|t| t.compute_pass_writes(index)),
        });
        pass.set_pipeline(&self.pipeline);
        for s in &self.instances {
            pass.set_bind_group(0, &s.group, &[]);
            pass.dispatch_workgroups(s.workgroups.0, s.workgroups.1, 1);
        }
    }
}

/// A deformed instance's vertices as the GPU computed them (read back).
#[derive(Debug, Clone)]
pub struct DeformedVertices {
    /// The scene's instance.
    pub instance: usize,
    /// Object space, as [`crate::scene::Pose::deformed_mesh`] (tangents `Some`
    /// when the mesh has them).
    pub now: crate::scene::PosedMesh,
    /// The positions one frame earlier (the motion vectors' previous positions).
    pub prev_positions: Vec<glam::Vec3>,
}

/// The vertices of the deformed (skinned, morphed) instances of `g` after the
/// last frame rendered, read back from the GPU (a blocking read; for tests and
/// inspection). Empty when the scene has none.
pub(crate) fn read_deformed(
    ctx: &GpuContext,
    g: &Geometry,
    scene: &Scene,
) -> Result<Vec<DeformedVertices>, RenderError> {
    let Some(prev_buffer) = &g.prev_vertex_buffer else {
        return Ok(Vec::new());
    };
    let stride = std::mem::size_of::<Vertex>() as u64;
    let read = |buffer: &wgpu::Buffer, d: &Deformed| -> Result<Vec<Vertex>, RenderError> {
        let bytes = ctx.read_buffer(
            buffer,
            u64::from(d.base) * stride,
            u64::from(d.vertices) * stride,
        )?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    };
    let mut out = Vec::with_capacity(g.deformed.len());
    for d in &g.deformed {
        let now = read(&g.vertex_buffer, d)?;
        let prev = read(prev_buffer, d)?;
        let has_tangents = scene
            .meshes
            .get(d.mesh)
            .is_some_and(|m| m.tangents.is_some());
        out.push(DeformedVertices {
            instance: d.instance,
            now: crate::scene::PosedMesh {
                positions: now.iter().map(|v| v.position.into()).collect(),
                normals: now.iter().map(|v| v.normal.into()).collect(),
                tangents: has_tangents.then(|| now.iter().map(|v| v.tangent.into()).collect()),
            },
            prev_positions: prev.iter().map(|v| v.position.into()).collect(),
        });
    }
    Ok(out)
}
