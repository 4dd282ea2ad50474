//! glTF materials and textures: the metallic-roughness material mapped onto the
//! `standard` surface and the `cook_torrance` lighting shader (with
//! `KHR_materials_emissive_strength`, `KHR_materials_ior`, `KHR_materials_specular`;
//! clear coat and transmission in `material_layers.rs`), `KHR_texture_transform` on
//! every texture, and images decoded to RGBA8.

use super::Converter;
use crate::scene::model::{AlphaMode, Material, TextureImage};
use glam::{Vec2, Vec3, Vec4};

impl Converter<'_> {
    fn texture(&mut self, tex: gltf::Texture, what: &str) -> Result<usize, String> {
        let image = tex.source().index();
        if let Some(&t) = self.textures.get(&image) {
            return Ok(t);
        }
        let data = self
            .images
            .get(image)
            .ok_or_else(|| format!("texture {} refers to missing image {image}", tex.index()))?;
        let rgba8 = to_rgba8(data).map_err(|e| format!("image {image} ({what}): {e}"))?;
        let source = tex.source();
        let name = match (source.name(), source.source()) {
            (Some(n), _) => n.to_string(),
            (None, gltf::image::Source::Uri { uri, .. }) if !uri.starts_with("data:") => {
                uri.to_string()
            }
            _ => format!("image {image}"),
        };
        self.scene.textures.push(TextureImage {
            name,
            width: data.width,
            height: data.height,
            rgba8,
        });
        let t = self.scene.textures.len() - 1;
        self.textures.insert(image, t);
        Ok(t)
    }

    /// Binds one texture reference to the standard surface: the texture variable,
    /// `VAR_uv` (the KHR_texture_transform matrix, columns) and `VAR_uv_offset`
    /// (offset, texture coordinate set).
    pub(super) fn bind_map(&mut self, m: &mut Material, r: &TexRef) -> Result<(), String> {
        let t = self.texture(r.texture.clone(), r.what)?;
        let set = self.uv_set(&m.name, r);
        let [c0x, c0y, c1x, c1y] = r.transform.matrix_columns();
        let [ox, oy] = r.transform.offset;
        m.surface.set_texture(r.var, t);
        m.surface.set(
            &format!("{}_uv", r.var),
            &[c0x, c0y, c1x, c1y].map(f64::from),
        );
        m.surface.set(
            &format!("{}_uv_offset", r.var),
            &[f64::from(ox), f64::from(oy), f64::from(set), 0.0],
        );
        Ok(())
    }

    /// The texture coordinate set a reference reads (0 or 1; larger sets are read
    /// as set 0 with a warning: only `TEXCOORD_0` and `TEXCOORD_1` are loaded).
    fn uv_set(&self, material: &str, r: &TexRef) -> u32 {
        let set = r.set();
        if set > 1 {
            log::warn!(
                "{}: {material}: the {} texture uses TEXCOORD_{set}; only sets 0 and 1 are \
                 supported, reading TEXCOORD_0",
                self.name,
                r.what
            );
            0
        } else {
            set
        }
    }

    /// Maps a glTF material onto the `standard` surface lit by `cook_torrance`
    /// (glTF 2.0 section 3.9 and Appendix B):
    ///
    /// - `base_color` = baseColorFactor, `base_color_map` = baseColorTexture (sRGB;
    ///   the surface multiplies factor, texture and `COLOR_0`);
    /// - `metallic` / `roughness` = metallicFactor / roughnessFactor,
    ///   `metallic_roughness_map` = metallicRoughnessTexture (B = metallic,
    ///   G = roughness, linear);
    /// - `normal_map` = normalTexture with `normal_scale` = its scale;
    /// - `occlusion_map` = occlusionTexture (R) with `occlusion_strength` = its
    ///   strength;
    /// - `emissive` = emissiveFactor × `KHR_materials_emissive_strength`,
    ///   `emissive_map` = emissiveTexture (sRGB);
    /// - `specular` = the dielectric F0: 0.04, or from `KHR_materials_ior`
    ///   (((ior − 1)/(ior + 1))²) and `KHR_materials_specular` factors
    ///   (min(F0_ior · specularColorFactor, 1) · specularFactor; the extension's
    ///   textures (logged) and its scaling of F90 (not modelled) are not supported);
    /// - every map's texCoord and `KHR_texture_transform` become `MAP_uv` and
    ///   `MAP_uv_offset` (see [`UvTransform`]);
    /// - alphaMode, alphaCutoff, doubleSided.
    pub(super) fn material(&mut self, mat: gltf::Material) -> Result<usize, String> {
        if let Some(&m) = self.materials.get(&mat.index()) {
            return Ok(m);
        }
        let name = mat
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| match mat.index() {
                Some(i) => format!("material {i}"),
                None => "default material".into(),
            });
        let pbr = mat.pbr_metallic_roughness();
        let base = Vec4::from(pbr.base_color_factor());
        let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
        if !base.is_finite() || !metallic.is_finite() || !roughness.is_finite() {
            return Err(format!("{name}: non-finite material factors"));
        }
        let mut m = Material::metallic_roughness(&name, base, metallic, roughness);
        let f0 = self.dielectric_f0(&mat, &name)?;
        m.surface.set("specular", &f0.to_array().map(f64::from));
        let strength = mat.emissive_strength().unwrap_or(1.0);
        let emissive = Vec3::from(mat.emissive_factor()) * strength;
        if !emissive.is_finite() || strength < 0.0 {
            return Err(format!(
                "{name}: invalid emissive (factor {:?}, strength {strength})",
                mat.emissive_factor()
            ));
        }
        m.surface
            .set("emissive", &emissive.to_array().map(f64::from));
        self.material_layers(&mat, &mut m, &name)?;
        for r in texture_refs(&mat).map_err(|e| format!("{name}: {e}"))? {
            self.bind_map(&mut m, &r)?;
        }
        if let Some(n) = mat.normal_texture() {
            if !n.scale().is_finite() {
                return Err(format!("{name}: non-finite normalTexture scale"));
            }
            m.surface.set("normal_scale", &[f64::from(n.scale())]);
        }
        if let Some(o) = mat.occlusion_texture() {
            if !o.strength().is_finite() {
                return Err(format!("{name}: non-finite occlusionTexture strength"));
            }
            m.surface
                .set("occlusion_strength", &[f64::from(o.strength())]);
        }
        m.alpha_mode = match mat.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        m.alpha_cutoff = mat.alpha_cutoff().unwrap_or(0.5);
        if !(m.alpha_cutoff.is_finite() && m.alpha_cutoff >= 0.0) {
            return Err(format!(
                "{name}: alphaCutoff {} must be a number >= 0",
                m.alpha_cutoff
            ));
        }
        m.double_sided = mat.double_sided();
        self.scene.materials.push(m);
        let index = self.scene.materials.len() - 1;
        self.materials.insert(mat.index(), index);
        Ok(index)
    }

    /// The dielectric specular reflectance F0: 0.04 (ior 1.5) unless
    /// `KHR_materials_ior` / `KHR_materials_specular` say otherwise.
    fn dielectric_f0(&self, mat: &gltf::Material, name: &str) -> Result<Vec3, String> {
        let ior = mat.ior().unwrap_or(1.5);
        if !(ior.is_finite() && (ior == 0.0 || ior >= 1.0)) {
            return Err(format!(
                "{name}: KHR_materials_ior ior {ior} must be 0 or >= 1"
            ));
        }
        // (The extension allows ior = 0, which gives F0 = 1.)
        let f0_ior = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let Some(s) = mat.specular() else {
            return Ok(Vec3::splat(f0_ior));
        };
        let color = Vec3::from(s.specular_color_factor());
        let factor = s.specular_factor();
        if !color.is_finite() || !factor.is_finite() || factor < 0.0 || color.min_element() < 0.0 {
            return Err(format!("{name}: invalid KHR_materials_specular factors"));
        }
        if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
            log::warn!(
                "{}: {name}: KHR_materials_specular textures are not supported (factors only)",
                self.name
            );
        }
        Ok((color * f0_ior).min(Vec3::ONE) * factor)
    }
}

/// A `KHR_texture_transform` (identity when absent): `uv' = M · uv + offset` with
/// `M = R(rotation) · S(scale)`.
///
/// The rotation turns the UVs by `rotation` radians "counter-clockwise" as seen in
/// glTF's UV space, whose V axis points *down*:
///
/// ```text
/// R = | cos r   sin r |      u' = cos r · sx · u + sin r · sy · v + offset.x
///     |-sin r   cos r |      v' = −sin r · sx · u + cos r · sy · v + offset.y
/// ```
///
/// This is the matrix of the extension's published example (offset (0, 1),
/// rotation π/2, scale 0.5 selects the lower-left quadrant of the image, rotated
/// clockwise 90°), of its sample model `TextureTransformTest` and of the common
/// implementations (three.js, Babylon.js, Blender). The GLSL listing in the
/// extension's README builds the transpose (a known mistake in the text,
/// KhronosGroup/glTF issue #1563), which would rotate the other way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvTransform {
    pub offset: [f32; 2],
    /// Radians.
    pub rotation: f32,
    pub scale: [f32; 2],
    /// The extension's `texCoord` override.
    pub tex_coord: Option<u32>,
}

impl UvTransform {
    /// No transform.
    pub const IDENTITY: UvTransform = UvTransform {
        offset: [0.0, 0.0],
        rotation: 0.0,
        scale: [1.0, 1.0],
        tex_coord: None,
    };

    /// `M = R · S` as its columns: `[m00, m10, m01, m11]` (first column in x, y,
    /// second in z, w).
    pub fn matrix_columns(&self) -> [f32; 4] {
        let (s, c) = self.rotation.sin_cos();
        let [sx, sy] = self.scale;
        [c * sx, -s * sx, s * sy, c * sy]
    }

    /// Applies the transform to one texture coordinate.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [a, b, c, d] = self.matrix_columns();
        Vec2::new(a * uv.x + c * uv.y, b * uv.x + d * uv.y) + Vec2::from(self.offset)
    }

    fn check(self, what: &str) -> Result<UvTransform, String> {
        let finite = self.offset.iter().chain(&self.scale).all(|v| v.is_finite())
            && self.rotation.is_finite();
        if finite {
            Ok(self)
        } else {
            Err(format!(
                "{what}: KHR_texture_transform has non-finite values"
            ))
        }
    }

    /// From a texture info's typed extension.
    fn from_info(info: &gltf::texture::Info, what: &str) -> Result<UvTransform, String> {
        match info.texture_transform() {
            None => Ok(UvTransform::IDENTITY),
            Some(t) => UvTransform {
                offset: t.offset(),
                rotation: t.rotation(),
                scale: t.scale(),
                tex_coord: t.tex_coord(),
            }
            .check(what),
        }
    }

    /// From the raw JSON of the extension (normal and occlusion texture infos,
    /// which the `gltf` crate leaves untyped).
    pub(super) fn from_json(
        value: Option<&serde_json::Value>,
        what: &str,
    ) -> Result<UvTransform, String> {
        let Some(value) = value else {
            return Ok(UvTransform::IDENTITY);
        };
        let obj = value
            .as_object()
            .ok_or_else(|| format!("{what}: KHR_texture_transform must be an object"))?;
        let pair = |key: &str, default: [f32; 2]| -> Result<[f32; 2], String> {
            match obj.get(key) {
                None => Ok(default),
                Some(v) => match v.as_array().map(|a| a.as_slice()) {
                    Some([x, y]) => match (x.as_f64(), y.as_f64()) {
                        (Some(x), Some(y)) => Ok([x as f32, y as f32]),
                        _ => Err(format!(
                            "{what}: KHR_texture_transform {key} must be two numbers"
                        )),
                    },
                    _ => Err(format!(
                        "{what}: KHR_texture_transform {key} must be two numbers"
                    )),
                },
            }
        };
        let rotation = match obj.get("rotation") {
            None => 0.0,
            Some(v) => v
                .as_f64()
                .ok_or_else(|| format!("{what}: KHR_texture_transform rotation must be a number"))?
                as f32,
        };
        let tex_coord =
            match obj.get("texCoord") {
                None => None,
                Some(v) => Some(v.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(
                    || format!("{what}: KHR_texture_transform texCoord must be an integer >= 0"),
                )?),
            };
        UvTransform {
            offset: pair("offset", [0.0, 0.0])?,
            rotation,
            scale: pair("scale", [1.0, 1.0])?,
            tex_coord,
        }
        .check(what)
    }
}

/// One texture reference of a material.
pub(super) struct TexRef<'a> {
    /// The standard surface's texture variable.
    pub(super) var: &'static str,
    /// For messages.
    pub(super) what: &'static str,
    pub(super) texture: gltf::Texture<'a>,
    /// The texture info's `texCoord`.
    pub(super) tex_coord: u32,
    pub(super) transform: UvTransform,
}

impl TexRef<'_> {
    /// The set read: the extension's override, else the info's `texCoord`.
    pub(super) fn set(&self) -> u32 {
        self.transform.tex_coord.unwrap_or(self.tex_coord)
    }
}

/// The texture references of a material that the standard surface uses.
pub(super) fn texture_refs<'a>(mat: &gltf::Material<'a>) -> Result<Vec<TexRef<'a>>, String> {
    let mut out = Vec::new();
    let pbr = mat.pbr_metallic_roughness();
    let infos = [
        (
            "base_color_map",
            "baseColorTexture",
            pbr.base_color_texture(),
        ),
        (
            "metallic_roughness_map",
            "metallicRoughnessTexture",
            pbr.metallic_roughness_texture(),
        ),
        ("emissive_map", "emissiveTexture", mat.emissive_texture()),
    ];
    for (var, what, info) in infos {
        if let Some(info) = info {
            out.push(TexRef {
                var,
                what,
                texture: info.texture(),
                tex_coord: info.tex_coord(),
                transform: UvTransform::from_info(&info, what)?,
            });
        }
    }
    // The normal and occlusion infos are other types, with the transform as JSON.
    let ext = "KHR_texture_transform";
    let (normal, occlusion) = (mat.normal_texture(), mat.occlusion_texture());
    let json_infos = [
        (
            "normal_map",
            "normalTexture",
            normal
                .as_ref()
                .map(|n| (n.texture(), n.tex_coord(), n.extension_value(ext))),
        ),
        (
            "occlusion_map",
            "occlusionTexture",
            occlusion
                .as_ref()
                .map(|o| (o.texture(), o.tex_coord(), o.extension_value(ext))),
        ),
    ];
    for (var, what, info) in json_infos {
        if let Some((texture, tex_coord, transform)) = info {
            out.push(TexRef {
                var,
                what,
                texture,
                tex_coord,
                transform: UvTransform::from_json(transform, what)?,
            });
        }
    }
    Ok(out)
}

/// Any decoded glTF image as RGBA8 (16-bit and float channels are scaled/clamped).
fn to_rgba8(d: &gltf::image::Data) -> Result<Vec<u8>, String> {
    use gltf::image::Format as F;
    let px = d.width as usize * d.height as usize;
    let (channels, bytes_per): (usize, usize) = match d.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    if d.pixels.len() < px * channels * bytes_per {
        return Err(format!(
            "{}x{} {:?} needs {} bytes, decoded {}",
            d.width,
            d.height,
            d.format,
            px * channels * bytes_per,
            d.pixels.len()
        ));
    }
    let sample = |i: usize| -> u8 {
        match bytes_per {
            1 => d.pixels[i],
            2 => d.pixels[i * 2 + 1],
            _ => {
                let b = &d.pixels[i * 4..i * 4 + 4];
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                (v.clamp(0.0, 1.0) * 255.0).round() as u8
            }
        }
    };
    let mut out = Vec::with_capacity(px * 4);
    for p in 0..px {
        let base = p * channels;
        let rgba = match channels {
            1 => {
                let v = sample(base);
                [v, v, v, 255]
            }
            2 => {
                let v = sample(base);
                [v, v, v, sample(base + 1)]
            }
            3 => [sample(base), sample(base + 1), sample(base + 2), 255],
            _ => [
                sample(base),
                sample(base + 1),
                sample(base + 2),
                sample(base + 3),
            ],
        };
        out.extend_from_slice(&rgba);
    }
    Ok(out)
}
