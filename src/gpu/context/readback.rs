//! Reading textures back: pending readbacks, buffer mapping with a timeout, row unpadding.

use super::*;

/// A texture copy encoded by [`GpuContext::encode_readback`], waiting to be read.
#[derive(Debug)]
pub struct PendingReadback {
    pub(super) device: wgpu::Device,
    pub(super) buffer: wgpu::Buffer,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) format: wgpu::TextureFormat,
    pub(super) unpadded_bytes_per_row: u32,
    pub(super) padded_bytes_per_row: u32,
}

impl PendingReadback {
    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Maps the buffer, waits for the copy and returns tightly packed rows.
    ///
    /// Call it only after the encoder holding the copy has been submitted.
    pub fn finish(self) -> Result<Vec<u8>, GpuError> {
        map_read(&self.device, &self.buffer)?;
        let out = {
            let mapped = self
                .buffer
                .get_mapped_range(..)
                .map_err(|e| GpuError::Map(e.to_string()))?;
            unpad_rows(
                &mapped,
                self.unpadded_bytes_per_row as usize,
                self.padded_bytes_per_row as usize,
                self.height as usize,
            )
        };
        self.buffer.unmap();
        Ok(out)
    }
}
pub(crate) fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<(), GpuError> {
    map_slice_read(device, &buffer.slice(..))
}

/// Maps `slice` for reading and waits for it, polling the device.
pub(super) fn map_slice_read(
    device: &wgpu::Device,
    slice: &wgpu::BufferSlice<'_>,
) -> Result<(), GpuError> {
    let (tx, rx) = mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver only goes away when we gave up waiting.
        let _ = tx.send(result);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Poll(e.to_string()))?;
    let deadline = Instant::now() + MAP_TIMEOUT;
    loop {
        match rx.try_recv() {
            Ok(result) => return result.map_err(|e| GpuError::Map(e.to_string())),
            Err(mpsc::TryRecvError::Disconnected) => {
                return Err(GpuError::Map("the map callback was dropped".to_string()))
            }
            // Another thread may be polling and running our callback; keep polling.
            Err(mpsc::TryRecvError::Empty) if Instant::now() < deadline => {
                device
                    .poll(wgpu::PollType::Poll)
                    .map_err(|e| GpuError::Poll(e.to_string()))?;
                std::thread::sleep(Duration::from_millis(1));
            }
            Err(mpsc::TryRecvError::Empty) => {
                return Err(GpuError::Map(format!(
                    "timed out after {} s waiting for the buffer mapping",
                    MAP_TIMEOUT.as_secs()
                )))
            }
        }
    }
}

/// Drops the row padding of a buffer copied with `padded` bytes per row.
pub(super) fn unpad_rows(data: &[u8], unpadded: usize, padded: usize, rows: usize) -> Vec<u8> {
    if unpadded == padded {
        return data[..unpadded * rows].to_vec();
    }
    let mut out = Vec::with_capacity(unpadded * rows);
    for row in data.chunks(padded).take(rows) {
        out.extend_from_slice(&row[..unpadded]);
    }
    out
}

impl GpuContext {
    /// Copies `size` bytes of `buffer` from `offset` (both multiples of 4; the
    /// buffer needs `COPY_SRC`) and returns them once the device has finished
    /// all work submitted before (a blocking read, for tests and inspection).
    pub fn read_buffer(
        &self,
        buffer: &wgpu::Buffer,
        offset: u64,
        size: u64,
    ) -> Result<Vec<u8>, GpuError> {
        if size == 0 {
            return Ok(Vec::new());
        }
        let staging = self.scoped("fxgraph buffer readback", |device| {
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fxgraph buffer readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("fxgraph buffer readback"),
            });
            encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
            self.queue.submit([encoder.finish()]);
            staging
        })?;
        map_read(&self.device, &staging)?;
        let bytes = staging
            .get_mapped_range(..)
            .map_err(|e| GpuError::Map(e.to_string()))?
            .to_vec();
        staging.unmap();
        Ok(bytes)
    }
}
