//! The per-frame light data on the GPU: the light array, the visible-index list
//! (forward loop and light volumes) and the cluster lists, each grown to a power
//! of two when a frame needs more, and group 0, which binds them.

use super::clusters::ClusterLists;
use super::gpu_types::GpuLight;
use super::shadow_pass::ShadowMaps;
use crate::gpu::context::GpuContext;

/// Storage buffers of the frame's lights.
pub(crate) struct LightBuffers {
    pub lights: wgpu::Buffer,
    pub visible: wgpu::Buffer,
    pub cluster_ranges: wgpu::Buffer,
    pub cluster_lights: wgpu::Buffer,
}

fn storage(device: &wgpu::Device, label: &str, bytes: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

const LIGHTS: &str = "deferred lights";
const VISIBLE: &str = "deferred visible light indices";
const RANGES: &str = "deferred cluster ranges";
const CLUSTER_LIGHTS: &str = "deferred cluster lights";

impl LightBuffers {
    /// Room for 64 lights and 64 KiB of cluster lists.
    pub fn new(device: &wgpu::Device) -> LightBuffers {
        LightBuffers {
            lights: storage(device, LIGHTS, 64 * std::mem::size_of::<GpuLight>() as u64),
            visible: storage(device, VISIBLE, 64 * 6 * 4),
            cluster_ranges: storage(device, RANGES, 1 << 16),
            cluster_lights: storage(device, CLUSTER_LIGHTS, 1 << 16),
        }
    }

    /// Writes the frame's lights, visible indices and cluster lists, replacing
    /// buffers that are too small. Returns whether one was replaced (group 0
    /// must then be rebuilt).
    pub fn upload(
        &mut self,
        ctx: &GpuContext,
        lights: &[GpuLight],
        visible: &[u32],
        clusters: Option<&ClusterLists>,
    ) -> bool {
        let device = &ctx.device;
        let mut grown = false;
        let mut ensure = |buffer: &mut wgpu::Buffer, label: &str, bytes: u64| {
            if bytes > buffer.size() {
                *buffer = storage(device, label, bytes.next_power_of_two());
                grown = true;
            }
        };
        ensure(
            &mut self.lights,
            LIGHTS,
            std::mem::size_of_val(lights) as u64,
        );
        ensure(
            &mut self.visible,
            VISIBLE,
            std::mem::size_of_val(visible) as u64,
        );
        if let Some(c) = clusters {
            ensure(
                &mut self.cluster_ranges,
                RANGES,
                std::mem::size_of_val(c.ranges.as_slice()) as u64,
            );
            ensure(
                &mut self.cluster_lights,
                CLUSTER_LIGHTS,
                std::mem::size_of_val(c.indices.as_slice()) as u64,
            );
        }
        let q = &ctx.queue;
        if !lights.is_empty() {
            q.write_buffer(&self.lights, 0, bytemuck::cast_slice(lights));
        }
        if !visible.is_empty() {
            q.write_buffer(&self.visible, 0, bytemuck::cast_slice(visible));
        }
        if let Some(c) = clusters {
            q.write_buffer(&self.cluster_ranges, 0, bytemuck::cast_slice(&c.ranges));
            if !c.indices.is_empty() {
                q.write_buffer(&self.cluster_lights, 0, bytemuck::cast_slice(&c.indices));
            }
        }
        grown
    }

    /// Group 0: frame uniforms, material infos, instances, these buffers, the
    /// shadow maps and the environment.
    #[allow(clippy::too_many_arguments)]
    pub fn group0(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
        material_info: &wgpu::Buffer,
        instances: &wgpu::Buffer,
        shadows: &ShadowMaps,
        environment: &super::environment::EnvironmentLighting,
    ) -> wgpu::BindGroup {
        let buffers = [
            frame,
            material_info,
            instances,
            &self.lights,
            &self.visible,
            &self.cluster_ranges,
            &self.cluster_lights,
        ];
        let mut entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        entries.extend(shadows.g0_entries());
        entries.extend(environment.g0_entries());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred group 0"),
            layout,
            entries: &entries,
        })
    }
}
