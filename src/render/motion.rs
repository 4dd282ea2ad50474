//! Motion vectors: the `AUX.motion` image (`Rg16Float`), in pixels, current minus
//! previous position, x right, y down: a pixel at p was at p − motion one frame
//! earlier (docs/renderer.md, "Motion vectors").
//!
//! Two steps after the technique's geometry passes, the same for all three
//! techniques (they all leave the frame's depth buffer):
//! 1. the AUX resolve pass (`fx_fs_aux_a`, shaders/light.wgsl), which reads the
//!    depth anyway, reprojects every pixel with the previous camera (static
//!    geometry and the background: camera motion alone) at the cost of one
//!    more render target;
//! 2. the instances that moved since the previous frame are drawn again with
//!    depth test `EQUAL`, their vertices projected with this frame's and the
//!    previous frame's transforms (`shaders/motion.wgsl`, this file).
//!
//! A still scene (or a moving camera over still instances) costs step 1 alone.
//! Transparent (BLEND) objects do not write depth: their pixels carry the motion
//! of what is behind them.

use super::gpu_types::{mat_array, Vertex};
use super::pipelines::{create, depth, storage_entry, target};
use super::upload::{Batch, Cull, Geometry};
use crate::gpu::bindings::uniform_entry;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use std::collections::HashMap;

/// Format of `AUX.motion`: half floats keep 0.05 px over ±64 px of motion.
pub(crate) const MOTION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;

const SHADER: &str = concat!(
    include_str!("../../shaders/render/instance.wgsl"),
    include_str!("../../shaders/render/motion.wgsl")
);

/// `MotionFrame` of motion.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuMotionFrame {
    view: [f32; 16],
    proj: [f32; 16],
    curr_vp: [f32; 16],
    prev_vp: [f32; 16],
    viewport: [f32; 4],
}

/// The matrices of one frame's motion vectors.
pub(crate) struct MotionCameras {
    /// As the geometry passes use them (the projection jittered).
    pub view: Mat4,
    pub proj: Mat4,
    /// Unjittered view-projections, now and one frame earlier.
    pub curr_vp: Mat4,
    pub prev_vp: Mat4,
}

/// Pipelines and buffers of the motion passes (made with the renderer).
pub(crate) struct MotionPass {
    uniforms: wgpu::Buffer,
    group0_layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    object: HashMap<Cull, wgpu::RenderPipeline>,
}

impl MotionPass {
    pub fn new(ctx: &GpuContext) -> Result<MotionPass, GpuError> {
        super::wgsl_check::check("motion vectors", SHADER).map_err(|message| {
            GpuError::Internal {
                what: "motion vectors".into(),
                message,
            }
        })?;
        let (uniforms, group0_layout, module) = ctx.scoped("motion vectors", |device| {
            let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("motion vector uniforms"),
                size: std::mem::size_of::<GpuMotionFrame>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group0_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("motion vectors group 0"),
                entries: &[
                    uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                    storage_entry(1),
                    storage_entry(2),
                ],
            });
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("motion vectors"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
            (uniforms, group0_layout, module)
        })?;
        Ok(MotionPass {
            uniforms,
            group0_layout,
            module,
            object: HashMap::new(),
        })
    }

    /// Makes the object pipelines `moving` needs (before [`MotionPass::encode`]).
    pub fn prepare(&mut self, ctx: &GpuContext, moving: &[Batch]) -> Result<(), GpuError> {
        for b in moving {
            self.object_pipeline(ctx, b.cull)?;
        }
        Ok(())
    }

    /// The object pipeline of a face-culling mode (made on first use).
    fn object_pipeline(&mut self, ctx: &GpuContext, cull: Cull) -> Result<(), GpuError> {
        if self.object.contains_key(&cull) {
            return Ok(());
        }
        let stride = std::mem::size_of::<Vertex>() as u64;
        let position = |location| wgpu::VertexBufferLayout {
            array_stride: stride,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: if location == 0 {
                &[wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x3,
                    offset: 0,
                    shader_location: 0,
                }]
            } else {
                &[wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x3,
                    offset: 0,
                    shader_location: 1,
                }]
            },
        };
        let pipeline = create(
            ctx,
            &format!("motion vectors: objects ({cull:?})"),
            &self.module,
            ("vs_object", "fs_object"),
            &[Some(position(0)), Some(position(1))],
            &[target(MOTION_FORMAT)],
            depth(false, wgpu::CompareFunction::Equal),
            cull.primitive(),
            &[Some(&self.group0_layout)],
            &[],
        )
        .map_err(|message| GpuError::Internal {
            what: "motion vectors: objects".into(),
            message,
        })?;
        self.object.insert(cull, pipeline);
        Ok(())
    }

    /// Writes the frame's matrices and viewport (`size` in pixels).
    fn write_uniforms(&self, ctx: &GpuContext, cams: &MotionCameras, size: (u32, u32)) {
        let (w, h) = (size.0 as f32, size.1 as f32);
        let frame = GpuMotionFrame {
            view: mat_array(cams.view),
            proj: mat_array(cams.proj),
            curr_vp: mat_array(cams.curr_vp),
            prev_vp: mat_array(cams.prev_vp),
            viewport: [w, h, 1.0 / w, 1.0 / h],
        };
        ctx.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&frame));
    }

    /// Group 0 of the object pass: the uniforms and the instance transforms
    /// now and one frame earlier.
    fn group0(&self, ctx: &GpuContext, geometry: &Geometry) -> Result<wgpu::BindGroup, GpuError> {
        ctx.scoped("motion vectors: bind group", |device| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("motion vectors group 0"),
                layout: &self.group0_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.uniforms.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: geometry.instance_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: geometry.prev_model_buffer.as_entire_binding(),
                    },
                ],
            })
        })
    }

    /// Records the object pass into `encoder` (after the resolve pass wrote the
    /// camera motion): `moving` lists the batches (one instance each) whose
    /// transforms changed since the previous frame ([`MotionPass::prepare`]d).
    /// Returns the draws.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &Geometry,
        cams: &MotionCameras,
        size: (u32, u32),
        depth_view: &wgpu::TextureView,
        motion_view: &wgpu::TextureView,
        moving: &[Batch],
        timer: Option<(&GpuTimer, u32)>,
    ) -> Result<usize, GpuError> {
        if moving.is_empty() {
            return Ok(0);
        }
        self.write_uniforms(ctx, cams, size);
        let g0 = self.group0(ctx, geometry)?;
        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("motion vectors: objects"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: motion_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth_view,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: timer.and_then(|(t, i)| t.pass_writes(i)),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rp.set_bind_group(0, &g0, &[]);
        rp.set_vertex_buffer(0, geometry.vertex_buffer.slice(..));
        rp.set_vertex_buffer(
            1,
            geometry
                .prev_vertex_buffer
                .as_ref()
                .unwrap_or(&geometry.vertex_buffer)
                .slice(..),
        );
        rp.set_index_buffer(geometry.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        for b in moving {
            rp.set_pipeline(&self.object[&b.cull]);
            rp.draw_indexed(b.indices.clone(), b.base_vertex, b.instances.clone());
        }
        Ok(moving.len())
    }
}
