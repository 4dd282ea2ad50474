//! Reading back the G-buffer as viewable images (`fxrun --scene S --gbuffer
//! DIR`; `crate::app` writes them as files).

use super::error::RenderError;
use super::output::RenderOutput;
use crate::gpu::context::GpuContext;
use crate::gpu::transfer::unpack_rgb10a2;
use crate::pixels::srgb::srgb_to_linear;
use crate::pixels::Pixels;

/// Reads a texture back as RGBA `f32` per pixel. sRGB formats are decoded to linear;
/// one-channel formats give `[r, 0, 0, 1]`; `Rgb10a2Unorm` gives the four unorm
/// channels. Supported: the renderer's colour formats (`Rgba8Unorm[Srgb]`,
/// `Rgb10a2Unorm`, `Rgba16Float`, `R16Float`, `R32Float`, `Rgba32Float`).
pub fn read_rgba_f32(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
) -> Result<Vec<[f32; 4]>, RenderError> {
    use wgpu::TextureFormat as F;
    let bytes = ctx.read_texture(texture)?;
    let format = texture.format();
    let out = match format {
        F::Rgba8Unorm => bytes
            .chunks_exact(4)
            .map(|p| [0, 1, 2, 3].map(|i| f32::from(p[i]) / 255.0))
            .collect(),
        F::Rgba8UnormSrgb => bytes
            .chunks_exact(4)
            .map(|p| {
                [
                    srgb_to_linear(f32::from(p[0]) / 255.0),
                    srgb_to_linear(f32::from(p[1]) / 255.0),
                    srgb_to_linear(f32::from(p[2]) / 255.0),
                    f32::from(p[3]) / 255.0,
                ]
            })
            .collect(),
        F::Rgb10a2Unorm => bytes.chunks_exact(4).map(unpack_rgb10a2).collect(),
        F::Rgba16Float => bytes
            .chunks_exact(8)
            .map(|p| {
                let h = |i: usize| half::f16::from_le_bytes([p[i], p[i + 1]]).to_f32();
                [h(0), h(2), h(4), h(6)]
            })
            .collect(),
        F::R16Float => bytes
            .chunks_exact(2)
            .map(|p| {
                [
                    half::f16::from_le_bytes([p[0], p[1]]).to_f32(),
                    0.0,
                    0.0,
                    1.0,
                ]
            })
            .collect(),
        F::Rg16Float => bytes
            .chunks_exact(4)
            .map(|p| {
                let h = |i: usize| half::f16::from_le_bytes([p[i], p[i + 1]]).to_f32();
                [h(0), h(2), 0.0, 1.0]
            })
            .collect(),
        F::R32Float => bytes
            .chunks_exact(4)
            .map(|p| [f32::from_le_bytes([p[0], p[1], p[2], p[3]]), 0.0, 0.0, 1.0])
            .collect(),
        F::Rgba32Float => bytes
            .chunks_exact(16)
            .map(|p| {
                let f = |i: usize| f32::from_le_bytes([p[i], p[i + 1], p[i + 2], p[i + 3]]);
                [f(0), f(4), f(8), f(12)]
            })
            .collect(),
        other => {
            return Err(RenderError::Invalid(format!(
                "cannot read back a {other:?} texture as floats"
            )))
        }
    };
    Ok(out)
}

fn to_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// A distinct colour per material id (background black).
fn id_colour(id: u32) -> [u8; 3] {
    let h = id.wrapping_mul(0x9E37_79B1).rotate_left(13) ^ 0x5bd1_e995;
    let c = |s: u32| 64 + ((h >> s) & 0xbf) as u8;
    [c(0), c(8), c(16)]
}

/// One viewable image of the G-buffer: its file name, pixels (RGBA, the render
/// size) and whether 8-bit pixels are linear already (written as they are).
pub struct GbufferImage {
    pub name: &'static str,
    pub pixels: Pixels,
    pub assume_linear: bool,
}

impl GbufferImage {
    fn new(name: &'static str, pixels: Pixels, assume_linear: bool) -> GbufferImage {
        GbufferImage {
            name,
            pixels,
            assume_linear,
        }
    }
}

/// Decodes every image of `output` into viewable images of the render size and
/// hands each to `emit` as soon as it is read back (the caller writes it; only
/// one or two images are held at a time). Stops at the first error of either.
///
/// - `depth.png` (linear depth normalised over the drawn pixels: near black, far
///   white; background white) and `depth.exr` (raw linear view depth);
/// - `normal.png` (view-space normal as `n·0.5 + 0.5`), `position.exr`;
/// - `motion.exr` (motion vectors in pixels: R = x, G = y, current minus
///   previous position, y down);
/// - `albedo.png`, `material_id.png` (false colour per id), `material.png`
///   (the material aux image's r, g, b: material id, lighting model id,
///   roughness), `specular.png` (mean F0);
/// - `gbuffer_normal_rgb10a2.png` (the raw target: encoded normal in rg,
///   roughness in b), `gbuffer_albedo_id.png` (raw diffuse target, rgb) and
///   `gbuffer_specular_model.png` (raw specular target: F0 in rgb);
/// - `light_diffuse.exr`, `light_specular.exr` (light accumulation buffers:
///   the lights, and emission + ambient in the specular one; deferred shading
///   adds the environment in its composition, and keeps the material's
///   occlusion in the specular buffer's alpha),
///   `scene.exr` (linear HDR) and `scene.png` (clamped, sRGB).
pub fn gbuffer_images<E: From<RenderError>>(
    output: &RenderOutput,
    ctx: &GpuContext,
    mut emit: impl FnMut(GbufferImage) -> Result<(), E>,
) -> Result<(), E> {
    let aux = |name: &str| {
        output
            .aux(name)
            .ok_or_else(|| RenderError::Invalid(format!("render output has no `{name}` image")))
    };
    let depth = read_rgba_f32(ctx, aux("depth")?)?;
    let normal = read_rgba_f32(ctx, aux("normal")?)?;
    let covered: Vec<bool> = normal.iter().map(|n| n[3] > 0.5).collect();
    for image in depth_images(&depth, &covered) {
        emit(image)?;
    }
    emit(normal_image(&normal, &covered))?;
    let position = read_rgba_f32(ctx, aux("position")?)?;
    emit(GbufferImage::new(
        "position.exr",
        rgb_f32(&position, |p| [p[0], p[1], p[2]]),
        true,
    ))?;
    // R = x, G = y in pixels (current − previous position, y down), B = 0
    let motion = read_rgba_f32(ctx, aux("motion")?)?;
    emit(GbufferImage::new(
        "motion.exr",
        rgb_f32(&motion, |m| [m[0], m[1], 0.0]),
        true,
    ))?;
    emit(GbufferImage::new(
        "albedo.png",
        Pixels::U8(opaque(
            ctx.read_texture(aux("albedo")?)
                .map_err(RenderError::from)?,
        )),
        false,
    ))?;
    let material = ctx
        .read_texture(aux("material")?)
        .map_err(RenderError::from)?;
    for image in material_images(&material, &covered) {
        emit(image)?;
    }
    let specular = read_rgba_f32(ctx, aux("specular")?)?;
    emit(GbufferImage::new(
        "specular.png",
        Pixels::U8(specular.iter().flat_map(|s| grey(to_u8(s[0]))).collect()),
        true,
    ))?;
    target_images(output, ctx, emit)
}

/// An opaque grey pixel.
fn grey(v: u8) -> [u8; 4] {
    [v, v, v, 255]
}

/// RGBA8 bytes with alpha set to opaque.
fn opaque(mut bytes: Vec<u8>) -> Vec<u8> {
    for px in bytes.chunks_exact_mut(4) {
        px[3] = 255;
    }
    bytes
}

/// Opaque float pixels of the three channels `rgb` takes from each value.
fn rgb_f32(values: &[[f32; 4]], rgb: impl Fn(&[f32; 4]) -> [f32; 3]) -> Pixels {
    Pixels::F32(
        values
            .iter()
            .flat_map(|v| {
                let [r, g, b] = rgb(v);
                [r, g, b, 1.0]
            })
            .collect(),
    )
}

/// `depth.png` (normalised over the drawn pixels, background white) and
/// `depth.exr` (raw).
fn depth_images(depth: &[[f32; 4]], covered: &[bool]) -> Vec<GbufferImage> {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for (d, &c) in depth.iter().zip(covered) {
        if c {
            lo = lo.min(d[0]);
            hi = hi.max(d[0]);
        }
    }
    let span = (hi - lo).max(1e-6);
    let normalised: Vec<u8> = depth
        .iter()
        .zip(covered)
        .flat_map(|(d, &c)| grey(if c { to_u8((d[0] - lo) / span) } else { 255 }))
        .collect();
    vec![
        GbufferImage::new("depth.png", Pixels::U8(normalised), true),
        GbufferImage::new("depth.exr", rgb_f32(depth, |d| [d[0], d[0], d[0]]), true),
    ]
}

/// `normal.png`: the view-space normal as `n·0.5 + 0.5`, background black.
fn normal_image(normal: &[[f32; 4]], covered: &[bool]) -> GbufferImage {
    let pixels = normal
        .iter()
        .zip(covered)
        .flat_map(|(n, &c)| {
            if c {
                [
                    to_u8(n[0] * 0.5 + 0.5),
                    to_u8(n[1] * 0.5 + 0.5),
                    to_u8(n[2] * 0.5 + 0.5),
                    255,
                ]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    GbufferImage::new("normal.png", Pixels::U8(pixels), true)
}

/// `material_id.png` (a false colour per id, background black) and
/// `material.png` (the material aux image's r, g, b).
fn material_images(material: &[u8], covered: &[bool]) -> Vec<GbufferImage> {
    let ids: Vec<u8> = material
        .chunks_exact(4)
        .zip(covered)
        .flat_map(|(m, &c)| {
            if c {
                let [r, g, b] = id_colour(u32::from(m[0]));
                [r, g, b, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    let rgb: Vec<u8> = material
        .chunks_exact(4)
        .flat_map(|m| [m[0], m[1], m[2], 255])
        .collect();
    vec![
        GbufferImage::new("material_id.png", Pixels::U8(ids), true),
        GbufferImage::new("material.png", Pixels::U8(rgb), true),
    ]
}

/// The raw G-buffer targets, the light accumulation buffers and the scene.
fn target_images<E: From<RenderError>>(
    output: &RenderOutput,
    ctx: &GpuContext,
    mut emit: impl FnMut(GbufferImage) -> Result<(), E>,
) -> Result<(), E> {
    let read = |t: &wgpu::Texture| ctx.read_texture(t).map_err(RenderError::from);
    let gnormal = read_rgba_f32(ctx, &output.gbuffer.normal)?;
    emit(GbufferImage::new(
        "gbuffer_normal_rgb10a2.png",
        Pixels::U8(
            gnormal
                .iter()
                .flat_map(|n| [to_u8(n[0]), to_u8(n[1]), to_u8(n[2]), 255])
                .collect(),
        ),
        true,
    ))?;
    emit(GbufferImage::new(
        "gbuffer_albedo_id.png",
        Pixels::U8(opaque(read(&output.gbuffer.albedo)?)),
        false,
    ))?;
    emit(GbufferImage::new(
        "gbuffer_specular_model.png",
        Pixels::U8(opaque(read(&output.gbuffer.specular)?)),
        false,
    ))?;
    for (name, tex) in [
        ("light_diffuse.exr", &output.gbuffer.light_diffuse),
        ("light_specular.exr", &output.gbuffer.light_specular),
        ("scene.exr", &output.scene),
        ("scene.png", &output.scene),
    ] {
        let v = read_rgba_f32(ctx, tex)?;
        emit(GbufferImage::new(
            name,
            rgb_f32(&v, |p| [p[0], p[1], p[2]]),
            false,
        ))?;
    }
    Ok(())
}
