//! GPU timing with timestamp queries.

use super::*;

/// GPU pass timing with timestamp queries: one begin/end pair per pass.
///
/// Use [`GpuTimer::pass_writes`] in each render pass, [`GpuTimer::resolve`] at the end
/// of the encoder, submit, then [`GpuTimer::read_ms`].
#[derive(Debug)]
pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve_buffer: wgpu::Buffer,
    readback_buffer: wgpu::Buffer,
    max_passes: u32,
}

impl GpuTimer {
    /// `None` when the device has no timestamp queries, `max_passes` is 0, or creating
    /// the query set fails. `max_passes` is capped at `QUERY_SET_MAX_QUERIES / 2`.
    pub fn new(ctx: &GpuContext, max_passes: u32) -> Option<Self> {
        if !ctx.timestamps || max_passes == 0 {
            return None;
        }
        let cap = wgpu::QUERY_SET_MAX_QUERIES / 2;
        if max_passes > cap {
            log::warn!("GPU timer: {max_passes} passes requested, timing only the first {cap}");
        }
        let max_passes = max_passes.min(cap);
        let bytes = u64::from(max_passes) * 2 * u64::from(wgpu::QUERY_SIZE);
        let created = ctx.scoped("GPU timer", |device| {
            let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fxgraph pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: max_passes * 2,
            });
            let resolve_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fxgraph timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fxgraph timestamp readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            GpuTimer {
                query_set,
                resolve_buffer,
                readback_buffer,
                max_passes,
            }
        });
        created
            .inspect_err(|e| log::warn!("GPU timing disabled: {e}"))
            .ok()
    }

    /// How many passes this timer can time.
    pub fn max_passes(&self) -> u32 {
        self.max_passes
    }

    /// Timestamp writes for pass `i` (`None` when `i >= max_passes`).
    pub fn pass_writes(&self, i: u32) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        (i < self.max_passes).then(|| wgpu::RenderPassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Timestamp writes for compute pass `i` (`None` when `i >= max_passes`).
    pub fn compute_pass_writes(&self, i: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        (i < self.max_passes).then(|| wgpu::ComputePassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Resolves the first `used` passes' timestamps and copies them to the readback
    /// buffer; encode it after the timed passes.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, used: u32) {
        let used = used.min(self.max_passes);
        if used == 0 {
            return;
        }
        encoder.resolve_query_set(&self.query_set, 0..2 * used, &self.resolve_buffer, 0);
        encoder.copy_buffer_to_buffer(
            &self.resolve_buffer,
            0,
            &self.readback_buffer,
            0,
            u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE),
        );
    }

    /// Milliseconds of the first `used` passes; call after the encoder with
    /// [`GpuTimer::resolve`] was submitted. Blocks until the GPU is done.
    pub fn read_ms(&self, ctx: &GpuContext, used: u32) -> Result<Vec<f64>, GpuError> {
        let used = used.min(self.max_passes);
        if used == 0 {
            return Ok(Vec::new());
        }
        let bytes = u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE);
        let slice = self.readback_buffer.slice(..bytes);
        map_slice_read(&ctx.device, &slice)?;
        self.mapped_ms(ctx, used)
    }

    /// Starts mapping the read-back buffer of the first `used` passes without
    /// waiting; call after the encoder with [`GpuTimer::resolve`] was submitted. The
    /// returned state becomes `Some` when the mapping is done (or failed): then
    /// [`GpuTimer::mapped_ms`] reads the times. The mapping completes while the
    /// device is polled (by any later submission, read-back or
    /// `Device::poll(PollType::Poll)`).
    pub fn map_async(&self, used: u32) -> Arc<Mutex<Option<Result<(), String>>>> {
        let used = used.min(self.max_passes).max(1);
        let bytes = u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE);
        let state = Arc::new(Mutex::new(None));
        let done = Arc::clone(&state);
        self.readback_buffer
            .slice(..bytes)
            .map_async(wgpu::MapMode::Read, move |result| {
                *done.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some(result.map_err(|e| e.to_string()));
            });
        state
    }

    /// Milliseconds of the first `used` passes from the mapped read-back buffer
    /// (after [`GpuTimer::map_async`] reported success); unmaps it.
    pub fn mapped_ms(&self, ctx: &GpuContext, used: u32) -> Result<Vec<f64>, GpuError> {
        let used = used.min(self.max_passes);
        if used == 0 {
            self.readback_buffer.unmap();
            return Ok(Vec::new());
        }
        let bytes = u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE);
        let slice = self.readback_buffer.slice(..bytes);
        let ticks: Vec<u64> = {
            let mapped = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Map(e.to_string()))?;
            mapped
                .chunks_exact(8)
                .map(bytemuck::pod_read_unaligned::<u64>)
                .collect()
        };
        self.readback_buffer.unmap();
        let period_ns = f64::from(ctx.queue.get_timestamp_period());
        Ok(ticks
            .chunks_exact(2)
            .map(|pair| pair[1].saturating_sub(pair[0]) as f64 * period_ns / 1e6)
            .collect())
    }
}
