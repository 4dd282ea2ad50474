//! Screenshots: the image shown (the output, an inspected pass, the input, an AUX
//! image) at its full resolution, read back and written as a normal run writes
//! its output (`io::save_image`, atomically): for the output, the same bytes a
//! run of the same frame writes to that file. Textures other than RGBA are written
//! as RGBA: one channel as grey, two as red and green.

use fxgraph::app::RunError;
use fxgraph::gpu::context::GpuContext;
use fxgraph::gpu::transfer::read_pixels;
use fxgraph::io::{self, SaveOptions};
use fxgraph::pixels::Pixels;
use fxgraph::script::types::Format;
use fxgraph::view::inspect::texel_values;
use std::path::{Path, PathBuf};

/// Read `texture` (in `format`) back and write it to `path`.
pub(super) fn save(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    format: Format,
    path: &Path,
    opts: &SaveOptions,
) -> Result<(), RunError> {
    let pixels = match format {
        // The window's copy of an 8-bit output is in BGRA order (present.rs).
        Format::Rgba8 | Format::Rgba8Srgb
            if matches!(
                texture.format(),
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            ) =>
        {
            let mut raw = ctx.read_texture(texture)?;
            for px in raw.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
            Pixels::U8(raw)
        }
        Format::Rgba8 | Format::Rgba8Srgb | Format::Rgba16f | Format::Rgba32f => {
            read_pixels(ctx, texture, format)?
        }
        other => {
            let raw = ctx.read_texture(texture)?;
            let (ch, v) = texel_values(&raw, other);
            let rgba: Vec<f32> = v
                .chunks_exact(ch)
                .flat_map(|px| match ch {
                    1 => [px[0], px[0], px[0], 1.0],
                    2 => [px[0], px[1], 0.0, 1.0],
                    _ => [px[0], px[1], px[2], px[3]],
                })
                .collect();
            Pixels::F32(rgba)
        }
    };
    io::save_image(path, texture.width(), texture.height(), &pixels, opts)?;
    Ok(())
}

/// `fxrun-view-NNNN.EXT` in the current folder, the first that does not exist
/// (EXT: png for 8-bit images, exr for float ones).
pub(super) fn next_free_name(format: Format) -> PathBuf {
    let ext = match format {
        Format::Rgba8 | Format::Rgba8Srgb | Format::R8 => "png",
        _ => "exr",
    };
    (1..)
        .map(|n| PathBuf::from(format!("fxrun-view-{n:04}.{ext}")))
        .find(|p| std::fs::symlink_metadata(p).is_err())
        .expect("a free name")
}
