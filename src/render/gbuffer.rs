//! Reading back and writing the G-buffer as viewable files (`fxrun --scene S
//! --gbuffer DIR`).

use super::error::RenderError;
use super::output::RenderOutput;
use crate::gpu::context::GpuContext;
use crate::gpu::transfer::unpack_rgb10a2;
use crate::io::{save_image, Pixels, SaveOptions};
use std::path::{Path, PathBuf};

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
                    crate::io::srgb::srgb_to_linear(f32::from(p[0]) / 255.0),
                    crate::io::srgb::srgb_to_linear(f32::from(p[1]) / 255.0),
                    crate::io::srgb::srgb_to_linear(f32::from(p[2]) / 255.0),
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

/// Decodes every image of `output` into viewable files in `dir` (created if
/// missing; each written atomically) and returns their paths:
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
/// - `light_diffuse.exr`, `light_specular.exr` (light accumulation buffers),
///   `scene.exr` (linear HDR) and `scene.png` (clamped, sRGB).
pub fn write_gbuffer(
    dir: &Path,
    output: &RenderOutput,
    ctx: &GpuContext,
) -> Result<Vec<PathBuf>, RenderError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        RenderError::Io(crate::io::IoError::Io {
            path: dir.to_path_buf(),
            source: e,
        })
    })?;
    let (w, h) = (output.width, output.height);
    let mut written = Vec::new();
    let mut save = |name: &str, pixels: Pixels, assume_linear: bool| -> Result<(), RenderError> {
        let path = dir.join(name);
        save_image(
            &path,
            w,
            h,
            &pixels,
            &SaveOptions {
                bit_depth: None,
                assume_linear,
            },
        )?;
        log::info!("wrote {}", path.display());
        written.push(path);
        Ok(())
    };
    let aux = |name: &str| {
        output
            .aux(name)
            .ok_or_else(|| RenderError::Invalid(format!("render output has no `{name}` image")))
    };
    let depth = read_rgba_f32(ctx, aux("depth")?)?;
    let normal = read_rgba_f32(ctx, aux("normal")?)?;
    let covered: Vec<bool> = normal.iter().map(|n| n[3] > 0.5).collect();
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for (d, &c) in depth.iter().zip(&covered) {
        if c {
            lo = lo.min(d[0]);
            hi = hi.max(d[0]);
        }
    }
    let span = (hi - lo).max(1e-6);
    let grey: Vec<u8> = depth
        .iter()
        .zip(&covered)
        .flat_map(|(d, &c)| {
            let v = if c { to_u8((d[0] - lo) / span) } else { 255 };
            [v, v, v, 255]
        })
        .collect();
    save("depth.png", Pixels::U8(grey), true)?;
    save(
        "depth.exr",
        Pixels::F32(depth.iter().flat_map(|d| [d[0], d[0], d[0], 1.0]).collect()),
        true,
    )?;
    save(
        "normal.png",
        Pixels::U8(
            normal
                .iter()
                .zip(&covered)
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
                .collect(),
        ),
        true,
    )?;
    let position = read_rgba_f32(ctx, aux("position")?)?;
    save(
        "position.exr",
        Pixels::F32(
            position
                .iter()
                .flat_map(|p| [p[0], p[1], p[2], 1.0])
                .collect(),
        ),
        true,
    )?;
    // R = x, G = y in pixels (current − previous position, y down), B = 0
    let motion = read_rgba_f32(ctx, aux("motion")?)?;
    save(
        "motion.exr",
        Pixels::F32(motion.iter().flat_map(|m| [m[0], m[1], 0.0, 1.0]).collect()),
        true,
    )?;
    let mut albedo = ctx.read_texture(aux("albedo")?)?;
    for px in albedo.chunks_exact_mut(4) {
        px[3] = 255;
    }
    save("albedo.png", Pixels::U8(albedo), false)?;
    let material = ctx.read_texture(aux("material")?)?;
    let ids: Vec<u8> = material
        .chunks_exact(4)
        .zip(&covered)
        .flat_map(|(m, &c)| {
            if c {
                let [r, g, b] = id_colour(u32::from(m[0]));
                [r, g, b, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    save("material_id.png", Pixels::U8(ids), true)?;
    save(
        "material.png",
        Pixels::U8(
            material
                .chunks_exact(4)
                .flat_map(|m| [m[0], m[1], m[2], 255])
                .collect(),
        ),
        true,
    )?;
    let specular = read_rgba_f32(ctx, aux("specular")?)?;
    save(
        "specular.png",
        Pixels::U8(
            specular
                .iter()
                .flat_map(|s| {
                    let v = to_u8(s[0]);
                    [v, v, v, 255]
                })
                .collect(),
        ),
        true,
    )?;
    let gnormal = read_rgba_f32(ctx, &output.gbuffer.normal)?;
    save(
        "gbuffer_normal_rgb10a2.png",
        Pixels::U8(
            gnormal
                .iter()
                .flat_map(|n| [to_u8(n[0]), to_u8(n[1]), to_u8(n[2]), 255])
                .collect(),
        ),
        true,
    )?;
    let mut galbedo = ctx.read_texture(&output.gbuffer.albedo)?;
    for px in galbedo.chunks_exact_mut(4) {
        px[3] = 255;
    }
    save("gbuffer_albedo_id.png", Pixels::U8(galbedo), false)?;
    let mut gspecular = ctx.read_texture(&output.gbuffer.specular)?;
    for px in gspecular.chunks_exact_mut(4) {
        px[3] = 255;
    }
    save("gbuffer_specular_model.png", Pixels::U8(gspecular), false)?;
    for (name, tex) in [
        ("light_diffuse.exr", &output.gbuffer.light_diffuse),
        ("light_specular.exr", &output.gbuffer.light_specular),
        ("scene.exr", &output.scene),
    ] {
        let v = read_rgba_f32(ctx, tex)?;
        save(
            name,
            Pixels::F32(v.iter().flat_map(|p| [p[0], p[1], p[2], 1.0]).collect()),
            false,
        )?;
    }
    let scene = read_rgba_f32(ctx, &output.scene)?;
    save(
        "scene.png",
        Pixels::F32(scene.iter().flat_map(|p| [p[0], p[1], p[2], 1.0]).collect()),
        false,
    )?;
    Ok(written)
}
