//! The split-sum DFG table (Karis 2013): for n·v and roughness, the terms A and B
//! of the glTF BRDF's specular albedo F0·A + B, computed once per renderer by
//! prefilter.wgsl's `fs_dfg`, in layer 0 of a 2D array texture whose layers
//! 1..=3 hold the lobe model's taps on the same grid (`lobe.rs`).

use super::lobe::{lobe_layer, LOBE_LAYERS};
use super::prefilter::{pass, GpuPrefilter, PrefilterPipelines, DFG_SAMPLES, DFG_SIZE, FORMAT};
use crate::gpu::context::{GpuContext, GpuError};

/// The table: [`DFG_SIZE`]², layer 0 rg = A, B; layers 1, 2, 3: the four
/// taps' offsets, roughnesses, weights (rgba = taps 0–3).
pub(crate) struct Dfg {
    pub texture: wgpu::Texture,
    /// All layers, as the shader reads them.
    pub view: wgpu::TextureView,
}

/// Layers of the DFG texture: the table and the lobe's taps.
pub(crate) const DFG_LAYERS: u32 = 1 + LOBE_LAYERS as u32;

/// The split-sum DFG table and the lobe's taps, computed once per renderer.
pub(crate) fn dfg_table(ctx: &GpuContext, pipes: &PrefilterPipelines) -> Result<Dfg, GpuError> {
    let made = ctx.scoped("environment DFG table", |device| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST;
        let label = "environment DFG table";
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: DFG_SIZE,
                height: DFG_SIZE,
                depth_or_array_layers: DFG_LAYERS,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("environment DFG table and lobe taps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let table = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("environment DFG table (layer 0)"),
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: 0,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("environment DFG table"),
        });
        pass(
            device,
            &mut encoder,
            &pipes.dfg,
            &table,
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
        for k in 0..LOBE_LAYERS {
            write_layer(ctx, &texture, 1 + k as u32, &lobe_layer(k, DFG_SIZE));
        }
        Dfg { texture, view }
    })?;
    Ok(made)
}

/// Uploads `texels` (RGBA f32 rows, [`DFG_SIZE`]²) into layer `layer`.
fn write_layer(ctx: &GpuContext, texture: &wgpu::Texture, layer: u32, texels: &[f32]) {
    let bytes: Vec<u8> = texels
        .iter()
        .flat_map(|v| half::f16::from_f32(*v).to_le_bytes())
        .collect();
    ctx.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            aspect: wgpu::TextureAspect::All,
        },
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(DFG_SIZE * 8),
            rows_per_image: Some(DFG_SIZE),
        },
        wgpu::Extent3d {
            width: DFG_SIZE,
            height: DFG_SIZE,
            depth_or_array_layers: 1,
        },
    );
}
