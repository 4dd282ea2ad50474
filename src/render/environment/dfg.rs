//! The split-sum DFG table (Karis 2013): for n·v and roughness, the terms A and B
//! of the glTF BRDF's specular albedo F0·A + B, computed once per renderer by
//! prefilter.wgsl's `fs_dfg`.

use super::prefilter::{pass, GpuPrefilter, PrefilterPipelines, DFG_SAMPLES, DFG_SIZE, FORMAT};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::transfer::texture_2d;

/// The table: [`DFG_SIZE`]², rg = A, B.
pub(crate) struct Dfg {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

/// The split-sum DFG table ([`DFG_SIZE`]², rg = A, B), computed once per renderer.
pub(crate) fn dfg_table(ctx: &GpuContext, pipes: &PrefilterPipelines) -> Result<Dfg, GpuError> {
    let made = ctx.scoped("environment DFG table", |device| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let size = (DFG_SIZE, DFG_SIZE);
        let label = "environment DFG table";
        let texture = device.create_texture(&texture_2d(label, size, FORMAT, usage, &[]));
        let view = texture.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("environment DFG table"),
        });
        pass(
            device,
            &mut encoder,
            &pipes.dfg,
            &view,
            Some(GpuPrefilter {
                face: 0,
                distribution: 0,
                samples: DFG_SAMPLES,
                _p0: 0,
                source_size: 0.0,
                roughness: 0.0,
                size: DFG_SIZE as f32,
                max_lod: 0.0,
            }),
            &[],
        );
        ctx.queue.submit([encoder.finish()]);
        Dfg { texture, view }
    })?;
    Ok(made)
}
