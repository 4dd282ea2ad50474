//! Scene textures on the GPU: mipmapped (box filter, in linear light for sRGB
//! data), each image created once per colour space it is sampled in.

use crate::gpu::context::{GpuContext, GpuError};
use crate::scene::Scene;
use std::collections::HashMap;

/// The scene's textures created so far, by (image index, sRGB).
pub(super) struct TextureCache<'s> {
    scene: &'s Scene,
    mipmaps: bool,
    views: HashMap<(usize, bool), wgpu::TextureView>,
}

impl<'s> TextureCache<'s> {
    pub fn new(scene: &'s Scene, mipmaps: bool) -> Self {
        TextureCache {
            scene,
            mipmaps,
            views: HashMap::new(),
        }
    }

    /// GPU textures created.
    pub fn len(&self) -> usize {
        self.views.len()
    }

    /// The view of `scene.textures[index]`, sampled as sRGB or linear data
    /// (created and uploaded on first use).
    pub fn view(
        &mut self,
        ctx: &GpuContext,
        index: usize,
        srgb: bool,
    ) -> Result<wgpu::TextureView, GpuError> {
        if let Some(v) = self.views.get(&(index, srgb)) {
            return Ok(v.clone());
        }
        let mipmaps = self.mipmaps;
        let t = &self.scene.textures[index];
        let levels = if mipmaps {
            32 - t.width.max(t.height).leading_zeros()
        } else {
            1
        };
        let format = if srgb {
            wgpu::TextureFormat::Rgba8UnormSrgb
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        };
        let label = format!(
            "deferred texture {} ({})",
            t.name,
            if srgb { "sRGB" } else { "linear" }
        );
        let view = ctx.scoped(&label, |device| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some(&label),
                size: wgpu::Extent3d {
                    width: t.width,
                    height: t.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: levels,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            for (level, (w, h, data)) in mip_chain(t.width, t.height, &t.rgba8, levels, srgb)
                .iter()
                .enumerate()
            {
                ctx.queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture: &texture,
                        mip_level: level as u32,
                        origin: wgpu::Origin3d::ZERO,
                        aspect: wgpu::TextureAspect::All,
                    },
                    data,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(w * 4),
                        rows_per_image: Some(*h),
                    },
                    wgpu::Extent3d {
                        width: *w,
                        height: *h,
                        depth_or_array_layers: 1,
                    },
                );
            }
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&label),
                ..Default::default()
            })
        })?;
        self.views.insert((index, srgb), view.clone());
        Ok(view)
    }
}

/// A box-filtered mip chain of RGBA8 data (level 0 first). With `srgb` the
/// colour channels are averaged in linear light (averaging the encoded values
/// would darken every level); alpha is always linear.
fn mip_chain(
    width: u32,
    height: u32,
    data: &[u8],
    levels: u32,
    srgb: bool,
) -> Vec<(u32, u32, Vec<u8>)> {
    let lut = crate::pixels::srgb::decode_lut_u8();
    let mut out = vec![(width, height, data.to_vec())];
    for _ in 1..levels {
        let (pw, ph, prev) = out.last().expect("level 0 exists");
        let (w, h) = ((pw / 2).max(1), (ph / 2).max(1));
        let mut next = vec![0u8; (w * h * 4) as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..4 {
                    let texel = |dx: u32, dy: u32| {
                        let sx = (x * 2 + dx).min(pw - 1);
                        let sy = (y * 2 + dy).min(ph - 1);
                        prev[((sy * pw + sx) * 4 + c) as usize]
                    };
                    let quad = [texel(0, 0), texel(1, 0), texel(0, 1), texel(1, 1)];
                    next[((y * w + x) * 4 + c) as usize] = if srgb && c < 3 {
                        let mean = quad.iter().map(|&v| lut[v as usize]).sum::<f32>() / 4.0;
                        crate::pixels::srgb::encode_u8(mean)
                    } else {
                        ((quad.iter().map(|&v| u32::from(v)).sum::<u32>() + 2) / 4) as u8
                    };
                }
            }
        }
        out.push((w, h, next));
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn srgb_mips_average_in_linear_light() {
        // a black/white checker: the linear mean is 0.5, sRGB-encoded 188
        let data: Vec<u8> = (0..4)
            .flat_map(|i| {
                if i == 0 || i == 3 {
                    [255u8; 4]
                } else {
                    [0, 0, 0, 255]
                }
            })
            .collect();
        let srgb = super::mip_chain(2, 2, &data, 2, true);
        assert_eq!(srgb[1].2, vec![188, 188, 188, 255]);
        let linear = super::mip_chain(2, 2, &data, 2, false);
        assert_eq!(linear[1].2, vec![128, 128, 128, 255]);
    }
}
