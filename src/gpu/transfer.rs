//! Images to textures and back: the texture format an [`Image`] is uploaded as, its
//! texel bytes, uploads, output textures and read-backs. Plain pixels in, plain
//! pixels out; files are the application's (`crate::app`).

use super::context::{GpuContext, GpuError};
use super::formats::wgpu_format;
use crate::pixels::{Image, Pixels};
use crate::script::types::{ColorSpace, Format};
use std::borrow::Cow;

/// The texture format an image is uploaded as, and what its samples mean: 8-bit
/// pixels as 8-bit textures; float pixels as rgba16f, except those decoded from integer
/// samples of more than 10 bits (12- and 16-bit y4m, 16-bit PNG, TIFF, PNM), which are
/// uploaded as rgba32f: a half float holds 11 significant bits, too few for them.
pub fn input_format(img: &Image, assume_linear: bool) -> (Format, ColorSpace) {
    match img.pixels {
        Pixels::U8(_) if assume_linear => (Format::Rgba8, ColorSpace::Linear),
        Pixels::U8(_) => (Format::Rgba8Srgb, ColorSpace::Linear),
        Pixels::F32(_) if !img.source.float && img.source.bit_depth > 10 => {
            (Format::Rgba32f, ColorSpace::Linear)
        }
        Pixels::F32(_) => (Format::Rgba16f, ColorSpace::Linear),
    }
}

/// Upload an image as a texture of `format` (from [`input_format`]).
pub fn upload_image(
    ctx: &GpuContext,
    label: &str,
    img: &Image,
    format: Format,
) -> Result<wgpu::Texture, GpuError> {
    let bytes = image_bytes(img, format);
    ctx.upload_texture(
        label,
        img.width,
        img.height,
        wgpu_format(format),
        &bytes,
        wgpu::TextureUsages::empty(),
    )
}

/// An image's pixels as the tightly packed texel bytes of `format` (from
/// [`input_format`]): 8-bit pixels as they are (borrowed, no copy), floats as half or
/// single floats with NaN as 0, 8-bit to float through the sRGB curve.
pub fn image_bytes(img: &Image, format: Format) -> Cow<'_, [u8]> {
    let finite = |x: f32| if x.is_nan() { 0.0 } else { x };
    let half = |v: &[f32]| -> Vec<u8> {
        v.iter()
            .flat_map(|&x| half::f16::from_f32(finite(x)).to_le_bytes())
            .collect()
    };
    let single =
        |v: &[f32]| -> Vec<u8> { v.iter().flat_map(|&x| finite(x).to_le_bytes()).collect() };
    match (&img.pixels, format) {
        (Pixels::U8(v), Format::Rgba8 | Format::Rgba8Srgb) => Cow::Borrowed(v),
        (Pixels::F32(v), Format::Rgba16f) => Cow::Owned(half(v)),
        (Pixels::F32(v), Format::Rgba32f) => Cow::Owned(single(v)),
        (p, Format::Rgba16f) => Cow::Owned(half(&p.to_f32_linear(false))),
        (p, _) => Cow::Owned(single(&p.to_f32_linear(false))),
    }
}

/// Read a texture back as pixels (U8 for 8-bit formats, linear F32 otherwise).
pub fn read_pixels(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    format: Format,
) -> Result<Pixels, GpuError> {
    pixels_from_bytes(ctx.read_texture(texture)?, format)
}

/// One little-endian `Rgb10a2Unorm` texel (`texel[..4]`) as its four unorm
/// channels: r, g, b in 10 bits, alpha in 2.
pub fn unpack_rgb10a2(texel: &[u8]) -> [f32; 4] {
    let v = u32::from_le_bytes([texel[0], texel[1], texel[2], texel[3]]);
    [
        (v & 1023) as f32 / 1023.0,
        ((v >> 10) & 1023) as f32 / 1023.0,
        ((v >> 20) & 1023) as f32 / 1023.0,
        (v >> 30) as f32 / 3.0,
    ]
}

/// Tightly packed texel bytes of `format` as pixels.
pub fn pixels_from_bytes(raw: Vec<u8>, format: Format) -> Result<Pixels, GpuError> {
    Ok(match format {
        Format::Rgba8 | Format::Rgba8Srgb => Pixels::U8(raw),
        Format::Rgba16f => Pixels::F32(
            raw.chunks_exact(2)
                .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
                .collect(),
        ),
        Format::Rgba32f => Pixels::F32(
            raw.chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        other => {
            return Err(GpuError::Map(format!(
                "cannot read back {other} as an image"
            )))
        }
    })
}

/// Create an output texture for a plan. A format the device can store to also
/// gets `STORAGE_BINDING`, so the pass writing it can be a compute dispatch
/// (compute execution, or a compute-native pass); a caller making its own output
/// texture adds that usage for the same effect. sRGB formats cannot be storage
/// textures: their last pass writes a stand-in copied into the output.
pub fn create_output(ctx: &GpuContext, width: u32, height: u32, format: Format) -> wgpu::Texture {
    // An sRGB output may be written through a raw 8-bit view (View::Raw).
    let view_formats: &[wgpu::TextureFormat] =
        if format == Format::Rgba8Srgb && ctx.info.backend != wgpu::Backend::Gl {
            &[wgpu::TextureFormat::Rgba8Unorm]
        } else {
            &[]
        };
    // COPY_DST: where the format cannot be stored to (sRGB), a compute pass
    // writes a stand-in that is copied into it (gpu/executor/stand_in.rs).
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::COPY_DST
        | wgpu::TextureUsages::TEXTURE_BINDING;
    if ctx.format_support(wgpu_format(format)).storage {
        usage |= wgpu::TextureUsages::STORAGE_BINDING;
    }
    let desc = texture_2d(
        "fxgraph output",
        (width, height),
        wgpu_format(format),
        usage,
        view_formats,
    );
    ctx.device.create_texture(&desc)
}

/// The descriptor of a plain 2D texture of `width` x `height` texels: one mip
/// level, one sample, one layer.
pub fn texture_2d<'a>(
    label: &'a str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    view_formats: &'a [wgpu::TextureFormat],
) -> wgpu::TextureDescriptor<'a> {
    wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats,
    }
}
