//! An RGBA texture to Y'CbCr planes: `shaders/yuv/rgb_to_yuv.wgsl` writes the
//! frame as a y4m frame stores it into one reused storage buffer, copied into a
//! read-back buffer from a pool (returned when the frame has been read), in the
//! same command encoder as the frame's passes.

use super::layout::{rgb_mode, Params, PlaneLayout};
use super::to_rgb::entry;
use super::{buffer, check_storage, compute_pipeline, YuvGpuError};
use crate::gpu::context::{map_read, GpuContext, GpuError};
use crate::script::types::Format;
use std::sync::{Arc, Mutex};

const LABEL: &str = "fxgraph rgb to yuv";

/// Read-back buffers not in use.
type Pool = Arc<Mutex<Vec<wgpu::Buffer>>>;

/// Converts textures of one format into frames of one [`PlaneLayout`].
pub struct RgbToPlanes {
    layout: PlaneLayout,
    format: Format,
    pipeline: wgpu::ComputePipeline,
    bind_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    taps: wgpu::Buffer,
    frame: wgpu::Buffer,
    /// Workgroups across and down.
    groups: (u32, u32),
    /// The texture last converted and its bind group.
    bound: Option<(wgpu::Texture, wgpu::BindGroup)>,
    pool: Pool,
}

/// A frame's planes copied into a read-back buffer, waiting for its submission.
#[derive(Debug)]
pub struct PendingPlanes {
    device: wgpu::Device,
    buffer: Option<wgpu::Buffer>,
    bytes: usize,
    pool: Pool,
}

impl RgbToPlanes {
    /// The pass and its buffers for textures of `format` (see
    /// [`super::PlanesToRgb::new`]) into frames of `layout`, their 4:2:0 chroma
    /// stored per field when `fields`. `Unavailable` when the device's buffers are
    /// too small for the frame, for another format, or for an 8-bit sRGB texture on
    /// a device without view formats (its raw codes cannot be read).
    pub fn new(
        ctx: &GpuContext,
        layout: &PlaneLayout,
        format: Format,
        fields: bool,
    ) -> Result<Self, YuvGpuError> {
        layout.check().map_err(YuvGpuError::Unavailable)?;
        let (rgb, _) = rgb_mode(format).ok_or_else(|| {
            YuvGpuError::Unavailable(format!("no conversion from {format} textures"))
        })?;
        if format == Format::Rgba8Srgb
            && (ctx.info.backend == wgpu::Backend::Gl
                || ctx.srgb_twin(wgpu::TextureFormat::Rgba8UnormSrgb).is_none())
        {
            return Err(YuvGpuError::Unavailable(
                "the device has no raw view of sRGB textures".into(),
            ));
        }
        let bytes = layout.frame_bytes().next_multiple_of(4);
        check_storage(ctx, "the output's planes", bytes)?;
        let words = (bytes / 4) as u32;
        let groups = words.div_ceil(64);
        let gx = groups.clamp(1, ctx.device.limits().max_compute_workgroups_per_dimension);
        let groups = (gx, groups.div_ceil(gx).max(1));
        let mut p = layout.params(fields, rgb);
        (p.words, p.groups_x) = (words, groups.0 * 64);
        let (pipeline, bind_layout) = compute_pipeline(
            ctx,
            LABEL,
            include_str!("../../../shaders/yuv/rgb_to_yuv.wgsl"),
        )?;
        let down = layout.down_table();
        let (params, taps, frame) = ctx.scoped(LABEL, |device| {
            use wgpu::BufferUsages as U;
            let params = buffer(
                device,
                "fxgraph rgb to yuv params",
                std::mem::size_of::<Params>() as u64,
                U::UNIFORM | U::COPY_DST,
            );
            let taps = buffer(
                device,
                "fxgraph yuv down taps",
                down.len() as u64,
                U::STORAGE | U::COPY_DST,
            );
            let frame = buffer(
                device,
                "fxgraph yuv planes",
                bytes,
                U::STORAGE | U::COPY_SRC,
            );
            ctx.queue.write_buffer(&params, 0, bytemuck::bytes_of(&p));
            ctx.queue.write_buffer(&taps, 0, &down);
            (params, taps, frame)
        })?;
        Ok(RgbToPlanes {
            layout: layout.clone(),
            format,
            pipeline,
            bind_layout,
            params,
            taps,
            frame,
            groups,
            bound: None,
            pool: Arc::default(),
        })
    }

    /// The layout of the frames made.
    pub fn layout(&self) -> &PlaneLayout {
        &self.layout
    }

    /// Encode the conversion of `texture` (its size the layout's, its format the
    /// one given to [`RgbToPlanes::new`]) and the copy of the planes into a
    /// read-back buffer; read them with [`PendingPlanes::finish`] once `enc` is
    /// submitted.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        enc: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Result<PendingPlanes, GpuError> {
        self.check_texture(texture)?;
        let bind_group = self.bind(ctx, texture)?;
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(LABEL),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(self.groups.0, self.groups.1, 1);
        }
        let size = self.frame.size();
        let reused = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop();
        let target = match reused {
            Some(b) => b,
            None => ctx.scoped("fxgraph yuv read-back buffer", |device| {
                use wgpu::BufferUsages as U;
                buffer(
                    device,
                    "fxgraph yuv read-back",
                    size,
                    U::MAP_READ | U::COPY_DST,
                )
            })?,
        };
        enc.copy_buffer_to_buffer(&self.frame, 0, &target, 0, size);
        Ok(PendingPlanes {
            device: ctx.device.clone(),
            buffer: Some(target),
            bytes: self.layout.frame_bytes() as usize,
            pool: self.pool.clone(),
        })
    }

    fn check_texture(&self, texture: &wgpu::Texture) -> Result<(), GpuError> {
        let want = crate::gpu::executor::wgpu_format(self.format);
        let size = (texture.width(), texture.height());
        if texture.format() != want || size != (self.layout.width, self.layout.height) {
            return Err(GpuError::Validation {
                what: LABEL.into(),
                message: format!(
                    "a {}x{} {:?} texture for {}x{} {want:?} frames",
                    size.0,
                    size.1,
                    texture.format(),
                    self.layout.width,
                    self.layout.height
                ),
            });
        }
        Ok(())
    }

    /// The bind group of `texture` (kept for the next frame: a stream's output is
    /// one texture), read through a raw view when it is 8-bit sRGB.
    fn bind(
        &mut self,
        ctx: &GpuContext,
        texture: &wgpu::Texture,
    ) -> Result<wgpu::BindGroup, GpuError> {
        if let Some((t, g)) = &self.bound {
            if t == texture {
                return Ok(g.clone());
            }
        }
        let group = ctx.scoped(LABEL, |device| {
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("fxgraph rgb to yuv source"),
                format: Some(texture.format().remove_srgb_suffix()),
                ..Default::default()
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(LABEL),
                layout: &self.bind_layout,
                entries: &[
                    entry(0, &self.params),
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    entry(2, &self.taps),
                    entry(3, &self.frame),
                ],
            })
        })?;
        self.bound = Some((texture.clone(), group.clone()));
        Ok(group)
    }
}

impl Drop for PendingPlanes {
    /// A read-back dropped unread (an output not written) gives its buffer back.
    fn drop(&mut self) {
        if let Some(buffer) = self.buffer.take() {
            self.pool
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(buffer);
        }
    }
}

impl PendingPlanes {
    /// Wait for the copy and return the frame's planes (Y, Cb, Cr as a y4m frame
    /// stores them); the read-back buffer goes back to the pool. Call it only
    /// after the encoder holding the copy has been submitted.
    pub fn finish(mut self) -> Result<Vec<u8>, GpuError> {
        let buffer = self
            .buffer
            .take()
            .ok_or_else(|| GpuError::Map("the planes were read already".into()))?;
        map_read(&self.device, &buffer)?;
        let out = buffer
            .get_mapped_range(..)
            .map_err(|e| GpuError::Map(e.to_string()))?[..self.bytes]
            .to_vec();
        buffer.unmap();
        self.pool
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(buffer);
        Ok(out)
    }
}
