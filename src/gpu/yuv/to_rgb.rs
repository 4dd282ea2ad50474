//! Y'CbCr planes to an RGBA texture: the frame's planes written into a buffer of the
//! upload ring and copied into the conversion's storage buffer,
//! `shaders/yuv/yuv_to_rgb.wgsl` making the texels into another, and a copy into
//! the target texture; one submission per frame.

use super::layout::{rgb_mode, Params, PlaneLayout};
use super::upload::UploadRing;
use super::{buffer, check_storage, compute_pipeline, YuvGpuError};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::executor::wgpu_format;
use crate::gpu::transfer::texture_2d;
use crate::script::types::Format;

const LABEL: &str = "fxgraph yuv to rgb";

/// Converts the frames of one [`PlaneLayout`] into textures of one format.
pub struct PlanesToRgb {
    layout: PlaneLayout,
    format: Format,
    rgb: u32,
    row_bytes: u32,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    planes: wgpu::Buffer,
    upload: UploadRing,
    texels: wgpu::Buffer,
    /// Whether the parameters last written were those of per-field chroma.
    fields_written: Option<bool>,
}

impl PlanesToRgb {
    /// The pass and its buffers for frames of `layout` into textures of `format`
    /// (rgba8-srgb or rgba8: the R'G'B' values as 8-bit codes; rgba16f or rgba32f:
    /// linear light, the sRGB curve decoded). `Unavailable` when the device's
    /// buffers are too small for the frame, or for another format.
    pub fn new(
        ctx: &GpuContext,
        layout: &PlaneLayout,
        format: Format,
    ) -> Result<Self, YuvGpuError> {
        layout.check().map_err(YuvGpuError::Unavailable)?;
        let (rgb, texel) = rgb_mode(format).ok_or_else(|| {
            YuvGpuError::Unavailable(format!("no conversion into {format} textures"))
        })?;
        let row_bytes = (layout.width * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let texel_bytes = u64::from(row_bytes) * u64::from(layout.height);
        check_storage(ctx, "the input's texels", texel_bytes)?;
        check_storage(ctx, "the input's planes", layout.frame_bytes())?;
        let (pipeline, bgl) = compute_pipeline(
            ctx,
            LABEL,
            include_str!("../../../shaders/yuv/yuv_to_rgb.wgsl"),
        )?;
        let up = layout.up_table();
        let (params, planes, upload, texels, bind_group) = ctx.scoped(LABEL, |device| {
            use wgpu::BufferUsages as U;
            let params = buffer(
                device,
                "fxgraph yuv to rgb params",
                std::mem::size_of::<Params>() as u64,
                U::UNIFORM | U::COPY_DST,
            );
            let planes = buffer(
                device,
                "fxgraph yuv planes upload",
                layout.frame_bytes(),
                U::STORAGE | U::COPY_DST,
            );
            let taps = buffer(
                device,
                "fxgraph yuv up taps",
                up.len() as u64,
                U::STORAGE | U::COPY_DST,
            );
            let texels = buffer(
                device,
                "fxgraph yuv to rgb texels",
                texel_bytes,
                U::STORAGE | U::COPY_SRC,
            );
            let upload = UploadRing::new(device, planes.size());
            ctx.queue.write_buffer(&taps, 0, &up);
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(LABEL),
                layout: &bgl,
                entries: &[
                    entry(0, &params),
                    entry(1, &planes),
                    entry(2, &taps),
                    entry(3, &texels),
                ],
            });
            (params, planes, upload, texels, bind_group)
        })?;
        Ok(PlanesToRgb {
            layout: layout.clone(),
            format,
            rgb,
            row_bytes,
            pipeline,
            bind_group,
            params,
            planes,
            upload,
            texels,
            fields_written: None,
        })
    }

    /// The format of the textures made.
    pub fn format(&self) -> Format {
        self.format
    }

    /// A texture the conversion can write: the format's, sampled and copied by the
    /// effect like an uploaded image (an sRGB format with its raw twin view where
    /// the device has view formats).
    pub fn create_texture(&self, ctx: &GpuContext, label: &str) -> Result<wgpu::Texture, GpuError> {
        let format = wgpu_format(self.format);
        let twin: Vec<wgpu::TextureFormat> = ctx.srgb_twin(format).into_iter().collect();
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC;
        ctx.check_size(self.layout.width, self.layout.height, label)?;
        ctx.scoped(label, |device| {
            let size = (self.layout.width, self.layout.height);
            device.create_texture(&texture_2d(label, size, format, usage, &twin))
        })
    }

    /// Convert one frame's planes (`[y, cb, cr]` as a y4m frame stores them; the
    /// chroma planes empty for luma-only frames) into `target` (made by
    /// [`PlanesToRgb::create_texture`]); `fields`: its 4:2:0 chroma is stored per
    /// field. One submission.
    pub fn convert(
        &mut self,
        ctx: &GpuContext,
        planes: [&[u8]; 3],
        fields: bool,
        target: &wgpu::Texture,
    ) -> Result<(), GpuError> {
        self.check_planes(planes)?;
        ctx.scoped(LABEL, |device| {
            let mut enc = device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(LABEL) });
            let slot = self.upload.write(device, planes, &mut enc, &self.planes)?;
            self.write_params(ctx, fields);
            self.encode(&mut enc, target);
            ctx.queue.submit([enc.finish()]);
            self.upload.remap(slot);
            Ok(())
        })?
    }

    fn check_planes(&self, planes: [&[u8]; 3]) -> Result<(), GpuError> {
        let got: u64 = planes.iter().map(|p| p.len() as u64).sum();
        if got != self.layout.frame_bytes() || planes[1].len() != planes[2].len() {
            return Err(GpuError::Validation {
                what: LABEL.into(),
                message: format!(
                    "planes of {} + {} + {} bytes for a {}x{} frame of {} bytes",
                    planes[0].len(),
                    planes[1].len(),
                    planes[2].len(),
                    self.layout.width,
                    self.layout.height,
                    self.layout.frame_bytes()
                ),
            });
        }
        Ok(())
    }

    fn write_params(&mut self, ctx: &GpuContext, fields: bool) {
        if self.fields_written == Some(fields) {
            return;
        }
        let mut p = self.layout.params(fields, self.rgb);
        p.row_words = self.row_bytes / 4;
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        self.fields_written = Some(fields);
    }

    fn encode(&self, enc: &mut wgpu::CommandEncoder, target: &wgpu::Texture) {
        let (w, h) = (self.layout.width, self.layout.height);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(LABEL),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        enc.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: &self.texels,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.row_bytes),
                    rows_per_image: None,
                },
            },
            target.as_image_copy(),
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
    }
}

/// A whole buffer at `binding`.
pub(super) fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
