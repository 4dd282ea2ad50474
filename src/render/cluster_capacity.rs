//! How many cluster entries to reserve, learnt from the GPU without waiting
//! for it: each frame's footprint clusters (the light view pass's bound on the
//! entries, `light_view_gpu.rs`) are copied into a small mappable buffer and
//! mapped in the background; a later frame reads them when the map is done and
//! grows the reservation before the camera needs it. A frame whose entries do
//! not fit the reservation still renders exactly: its lists fall back to every
//! light (`clusters.wgsl`, fx_cs_cluster_offsets), and the next frames grow.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The background readback of the footprint clusters.
pub(crate) struct CapacityFeedback {
    staging: wgpu::Buffer,
    /// A copy was encoded into `staging` and not yet mapped.
    copied: Cell<bool>,
    /// The map was requested: set by its callback when done.
    mapped: Option<Arc<AtomicBool>>,
}

impl CapacityFeedback {
    pub fn new(device: &wgpu::Device) -> CapacityFeedback {
        CapacityFeedback {
            staging: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light clusters capacity readback"),
                size: 8,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            copied: Cell::new(false),
            mapped: None,
        }
    }

    /// Encodes the copy of the footprint clusters (word 5 of `summary`)
    /// unless an earlier one is still on its way.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, summary: &wgpu::Buffer) {
        if self.copied.get() || self.mapped.is_some() {
            return;
        }
        encoder.copy_buffer_to_buffer(summary, 20, &self.staging, 0, 4);
        self.copied.set(true);
    }

    /// Requests the map of the copy encoded (once the frame was submitted).
    pub fn after_submit(&mut self) {
        if !self.copied.take() {
            return;
        }
        let done = Arc::new(AtomicBool::new(false));
        let flag = done.clone();
        self.staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |result| {
                if result.is_ok() {
                    flag.store(true, Ordering::Release);
                }
            });
        self.mapped = Some(done);
    }

    /// The footprint clusters of an earlier frame, when their map is done
    /// (polls the device without waiting).
    pub fn poll(&mut self, device: &wgpu::Device) -> Option<u32> {
        let done = self.mapped.as_ref()?;
        if !done.load(Ordering::Acquire) {
            let _ = device.poll(wgpu::PollType::Poll);
            if !done.load(Ordering::Acquire) {
                return None;
            }
        }
        self.mapped = None;
        let value = self
            .staging
            .get_mapped_range(..)
            .ok()
            .map(|bytes| bytemuck::pod_read_unaligned::<u32>(&bytes[..4]));
        self.staging.unmap();
        value
    }
}
