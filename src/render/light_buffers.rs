//! The per-frame light data on the GPU: the light array and the visible-index
//! list (forward loop and light volumes), each grown to a power of two when a
//! frame needs more, and group 0, which binds them with the cluster lists the
//! GPU builds (`cluster_gpu.rs`).

use super::cluster_gpu::GpuClusters;
use super::gpu_types::GpuLight;
use super::shadow_pass::ShadowMaps;
use crate::gpu::context::GpuContext;

/// Storage buffers of the frame's lights.
pub(crate) struct LightBuffers {
    pub lights: wgpu::Buffer,
    pub visible: wgpu::Buffer,
    /// What the buffers hold (the last frame's lists).
    written_lights: Vec<GpuLight>,
    written_visible: Vec<u32>,
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

impl LightBuffers {
    /// Room for 64 lights.
    pub fn new(device: &wgpu::Device) -> LightBuffers {
        LightBuffers {
            lights: storage(device, LIGHTS, 64 * std::mem::size_of::<GpuLight>() as u64),
            visible: storage(device, VISIBLE, 64 * 6 * 4),
            written_lights: Vec::new(),
            written_visible: Vec::new(),
        }
    }

    /// Writes the frame's lights and visible indices, replacing buffers that
    /// are too small. Returns whether one was replaced (group 0 must then be
    /// rebuilt).
    pub fn upload(&mut self, ctx: &GpuContext, lights: &[GpuLight], visible: &[u32]) -> bool {
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
        // Only what changed is written (a still camera over still lights
        // writes nothing; the lights are in view space, so a moving camera
        // writes them all).
        let q = &ctx.queue;
        if !lights.is_empty() && (grown || self.written_lights.as_slice() != lights) {
            q.write_buffer(&self.lights, 0, bytemuck::cast_slice(lights));
            self.written_lights.clear();
            self.written_lights.extend_from_slice(lights);
        }
        if !visible.is_empty() && (grown || self.written_visible.as_slice() != visible) {
            q.write_buffer(&self.visible, 0, bytemuck::cast_slice(visible));
            self.written_visible.clear();
            self.written_visible.extend_from_slice(visible);
        }
        grown
    }

    /// Group 0: frame uniforms, material infos, instances, the light array
    /// (`lights`: this one, or the light view pass's with cluster lists), the
    /// visible indices, the cluster lists, the shadow maps and the environment.
    #[allow(clippy::too_many_arguments)] // one argument per owner of a binding
    pub fn group0(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
        material_info: &wgpu::Buffer,
        instances: &wgpu::Buffer,
        lights: &wgpu::Buffer,
        clusters: &GpuClusters,
        shadows: &ShadowMaps,
        environment: &super::environment::EnvironmentLighting,
    ) -> wgpu::BindGroup {
        let (cluster_ranges, cluster_lights) = clusters.lists();
        let buffers = [
            frame,
            material_info,
            instances,
            lights,
            &self.visible,
            cluster_ranges,
            cluster_lights,
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
