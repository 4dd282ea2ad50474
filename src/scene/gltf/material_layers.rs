//! The layers of a glTF material: `KHR_materials_clearcoat` and
//! `KHR_materials_transmission`, read from the material's raw extension JSON (the
//! `gltf` crate types neither with our features) onto the `standard` surface's
//! `clearcoat*` and `transmission*` settings. The engine shades them
//! (`shaders/render/layers.wgsl`, docs/materials.md).

use super::material::{TexRef, UvTransform};
use super::Converter;
use crate::scene::model::Material;
use serde_json::{Map, Value};

/// `KHR_materials_clearcoat`'s textures: (JSON key, standard surface variable).
const CLEARCOAT_MAPS: [(&str, &str); 3] = [
    ("clearcoatTexture", "clearcoat_map"),
    ("clearcoatRoughnessTexture", "clearcoat_roughness_map"),
    ("clearcoatNormalTexture", "clearcoat_normal_map"),
];

impl<'a> Converter<'a> {
    /// Sets the clear coat and the transmission of material `m` (named `name`)
    /// from glTF material `mat`:
    ///
    /// - `KHR_materials_clearcoat`: `clearcoat` = clearcoatFactor (default 0),
    ///   `clearcoat_roughness` = clearcoatRoughnessFactor (default 0), the maps
    ///   clearcoatTexture (R), clearcoatRoughnessTexture (G) and
    ///   clearcoatNormalTexture with `clearcoat_normal_scale` = its scale;
    /// - `KHR_materials_transmission`: `transmission` = transmissionFactor
    ///   (default 0) and `transmission_map` = transmissionTexture (R).
    ///
    /// Factors must be numbers in [0, 1]; each texture info is checked as the core
    /// ones are (index, texCoord, `KHR_texture_transform`).
    pub(super) fn material_layers(
        &mut self,
        mat: &gltf::Material,
        m: &mut Material,
        name: &str,
    ) -> Result<(), String> {
        if let Some(ext) = mat.extension_value("KHR_materials_clearcoat") {
            let what = "KHR_materials_clearcoat";
            let obj = object(ext, &format!("{name}: {what}"))?;
            let factor = unit_factor(obj, "clearcoatFactor", name, what)?;
            let roughness = unit_factor(obj, "clearcoatRoughnessFactor", name, what)?;
            m.surface.set("clearcoat", &[factor]);
            m.surface.set("clearcoat_roughness", &[roughness]);
            for (key, var) in CLEARCOAT_MAPS {
                if let Some(info) = obj.get(key) {
                    let r = self.json_texture(info, var, key, name)?;
                    self.bind_map(m, &r)?;
                }
            }
            if let Some(info) = obj.get("clearcoatNormalTexture") {
                let scale = match info.get("scale") {
                    None => 1.0,
                    Some(v) => v.as_f64().filter(|s| s.is_finite()).ok_or_else(|| {
                        format!("{name}: {what} clearcoatNormalTexture scale must be a number")
                    })?,
                };
                m.surface.set("clearcoat_normal_scale", &[scale]);
            }
        }
        if let Some(ext) = mat.extension_value("KHR_materials_transmission") {
            let what = "KHR_materials_transmission";
            let obj = object(ext, &format!("{name}: {what}"))?;
            let factor = unit_factor(obj, "transmissionFactor", name, what)?;
            m.surface.set("transmission", &[factor]);
            if let Some(info) = obj.get("transmissionTexture") {
                let r = self.json_texture(info, "transmission_map", "transmissionTexture", name)?;
                self.bind_map(m, &r)?;
            }
            if factor > 0.0 {
                log::warn!(
                    "{}: {name}: note: KHR_materials_transmission shows the environment map \
                     through the surface (thin-walled, blurred by its roughness), not the \
                     objects behind it",
                    self.name
                );
            }
        }
        Ok(())
    }

    /// A texture info given as raw JSON (`{"index", "texCoord", "extensions":
    /// {"KHR_texture_transform"}}`) for the standard surface's variable `var`.
    fn json_texture(
        &self,
        info: &Value,
        var: &'static str,
        what: &'static str,
        name: &str,
    ) -> Result<TexRef<'a>, String> {
        let obj = object(info, &format!("{name}: {what}"))?;
        let index = obj
            .get("index")
            .and_then(Value::as_u64)
            .ok_or_else(|| format!("{name}: {what} needs an integer index"))?;
        let texture = usize::try_from(index)
            .ok()
            .and_then(|i| self.document.textures().nth(i))
            .ok_or_else(|| format!("{name}: {what} refers to missing texture {index}"))?;
        let tex_coord = match obj.get("texCoord") {
            None => 0,
            Some(v) => v
                .as_u64()
                .and_then(|n| u32::try_from(n).ok())
                .ok_or_else(|| format!("{name}: {what} texCoord must be an integer >= 0"))?,
        };
        let transform = UvTransform::from_json(
            obj.get("extensions")
                .and_then(|e| e.get("KHR_texture_transform")),
            &format!("{name}: {what}"),
        )?;
        Ok(TexRef {
            var,
            what,
            texture,
            tex_coord,
            transform,
        })
    }
}

fn object<'v>(value: &'v Value, what: &str) -> Result<&'v Map<String, Value>, String> {
    value
        .as_object()
        .ok_or_else(|| format!("{what} must be an object"))
}

/// Factor `key` of an extension object: a number in [0, 1], 0 when absent.
fn unit_factor(obj: &Map<String, Value>, key: &str, name: &str, what: &str) -> Result<f64, String> {
    match obj.get(key) {
        None => Ok(0.0),
        Some(v) => v
            .as_f64()
            .filter(|f| (0.0..=1.0).contains(f))
            .ok_or_else(|| format!("{name}: {what} {key} {v} must be a number in [0, 1]")),
    }
}
