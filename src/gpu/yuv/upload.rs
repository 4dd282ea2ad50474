//! The upload ring: buffers mapped for writing that take one frame's planes each,
//! copied on the device into the conversion's storage buffer. A buffer is mapped
//! again as soon as its copy is submitted (ready once the device has run it), so
//! several frames are in flight and no buffer is made per frame.

use crate::gpu::context::GpuError;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Buffers in the ring: the frame being written and two in flight.
const SLOTS: usize = 3;

/// How long a buffer's mapping may take.
const MAP_TIMEOUT: Duration = Duration::from_secs(120);

/// A buffer's mapping: `None` while it is pending, then its outcome.
type Mapping = Arc<Mutex<Option<Result<(), String>>>>;

struct Slot {
    buffer: wgpu::Buffer,
    mapping: Mapping,
}

/// Upload buffers of one frame's size, used in turn.
pub(super) struct UploadRing {
    slots: Vec<Slot>,
    next: usize,
}

impl UploadRing {
    /// `SLOTS` buffers of `size` bytes (a multiple of 4), mapped.
    pub(super) fn new(device: &wgpu::Device, size: u64) -> UploadRing {
        let slots = (0..SLOTS)
            .map(|i| Slot {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("fxgraph yuv upload {i}")),
                    size,
                    usage: wgpu::BufferUsages::MAP_WRITE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: true,
                }),
                mapping: Arc::new(Mutex::new(Some(Ok(())))),
            })
            .collect();
        UploadRing { slots, next: 0 }
    }

    /// Write `planes` one after the other into the next buffer (waiting for its
    /// mapping) and encode its copy into `target`; returns the slot to pass to
    /// [`UploadRing::remap`] once `enc` is submitted.
    pub(super) fn write(
        &mut self,
        device: &wgpu::Device,
        planes: [&[u8]; 3],
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::Buffer,
    ) -> Result<usize, GpuError> {
        let slot = self.next;
        self.next = (self.next + 1) % SLOTS;
        let s = &self.slots[slot];
        wait_mapped(device, &s.mapping)?;
        {
            let mut view = s
                .buffer
                .get_mapped_range_mut(..)
                .map_err(|e| GpuError::Map(e.to_string()))?;
            let mut at = 0;
            for p in planes {
                view.slice(at..at + p.len()).copy_from_slice(p);
                at += p.len();
            }
            let pad = view.len() - at;
            view.slice(at..).copy_from_slice(&[0u8; 4][..pad.min(4)]);
        }
        s.buffer.unmap();
        *s.mapping.lock().unwrap_or_else(|e| e.into_inner()) = None;
        enc.copy_buffer_to_buffer(&s.buffer, 0, target, 0, s.buffer.size());
        Ok(slot)
    }

    /// Map `slot`'s buffer again (after the submission that copies it).
    pub(super) fn remap(&self, slot: usize) {
        let s = &self.slots[slot];
        let mapping = s.mapping.clone();
        s.buffer.map_async(wgpu::MapMode::Write, .., move |r| {
            *mapping.lock().unwrap_or_else(|e| e.into_inner()) = Some(r.map_err(|e| e.to_string()));
        });
    }
}

/// Wait for a mapping, polling the device.
fn wait_mapped(device: &wgpu::Device, mapping: &Mapping) -> Result<(), GpuError> {
    let deadline = Instant::now() + MAP_TIMEOUT;
    let mut first = true;
    loop {
        if let Some(r) = mapping.lock().unwrap_or_else(|e| e.into_inner()).clone() {
            return r.map_err(GpuError::Map);
        }
        if Instant::now() > deadline {
            return Err(GpuError::Map(format!(
                "timed out after {} s waiting for an upload buffer",
                MAP_TIMEOUT.as_secs()
            )));
        }
        let poll = if first {
            wgpu::PollType::wait_indefinitely()
        } else {
            std::thread::sleep(Duration::from_millis(1));
            wgpu::PollType::Poll
        };
        first = false;
        device
            .poll(poll)
            .map_err(|e| GpuError::Poll(e.to_string()))?;
    }
}
