//! The material system (the materials-and-effects paper, section 2) on the renderer's side: the scene's
//! materials resolved to their surface and lighting shaders, parameter blocks
//! packed, feature flags chosen, and the full shaders generated from templates.
//!
//! - [`variant`]: the three feature-selection modes and the variant keys.
//! - [`template`]: WGSL generation (geometry passes, light pass).
//! - this file: [`MaterialSet`], built once per scene.
//!
//! Lighting model ids are indices into [`MaterialSet::lightings`]: the distinct
//! lighting shaders of the scene, so the deferred light pass is compiled with
//! exactly the models present.

pub mod template;
pub mod variant;

pub use variant::{VariantKey, VariantMode, ENGINE_FLAGS};

use crate::scene::{AlphaMode, Material, Scene, ShaderBinding};
use crate::script::diag::{Diagnostics, SourceMap};
use crate::shader::material::{MaterialShader, MaterialShaderKind};
use crate::shader::reflect::FieldType;
use std::path::{Path, PathBuf};

/// A surface or lighting shader as the renderer uses it.
#[derive(Debug, Clone)]
pub struct ShaderInfo {
    pub name: String,
    /// The folder a user's shader was looked up in.
    pub dir: Option<PathBuf>,
    pub shader: MaterialShader,
    /// Feature flags in bit order: [`ENGINE_FLAGS`], then `HAS_<TEXTURE>` for every
    /// texture the shader declares (surfaces; lighting shaders have the engine
    /// flags only, which they cannot test).
    pub flags: Vec<String>,
}

/// Finds and checks material shader `name` (a user's `NAME.wgsl` under `dir`
/// first, then the built-in library); problems come back as a rendered report
/// with file:line:col.
pub fn load_shader(
    kind: MaterialShaderKind,
    name: &str,
    dir: Option<&Path>,
) -> Result<MaterialShader, String> {
    let Some(file) = crate::shader::material::find_material_shader(name, dir) else {
        return Err(format!(
            "no {} shader `{name}` (built-in: {}; a user's is `{name}.wgsl` next to the material file)",
            kind.name(),
            crate::shader::material::builtin_material_shaders().join(", ")
        ));
    };
    let mut sources = SourceMap::new();
    crate::shader::material::load_material_shader(kind, name, file, &mut sources)
        .map_err(|d| Diagnostics { list: d }.render(&sources))
}

impl ShaderInfo {
    fn new(name: &str, dir: Option<PathBuf>, shader: MaterialShader) -> ShaderInfo {
        let flags = if shader.flags.is_empty() {
            ENGINE_FLAGS.iter().map(|s| s.to_string()).collect()
        } else {
            shader.flags.clone()
        };
        ShaderInfo {
            name: name.to_string(),
            dir,
            shader,
            flags,
        }
    }

    /// Whether `lighting` takes a `LightingParams` argument.
    pub fn takes_params(&self) -> bool {
        self.shader.lighting_takes_params
    }

    /// Bit of feature `flag` (None: not a flag of this shader).
    pub fn bit(&self, flag: &str) -> Option<u64> {
        self.flags.iter().position(|f| f == flag).map(|i| 1 << i)
    }

    /// Bytes of the parameter struct (0 without one).
    pub fn params_size(&self) -> usize {
        self.shader.params.as_ref().map_or(0, |p| p.size as usize)
    }

    /// Array stride of the parameter struct in a storage buffer.
    pub fn params_stride(&self) -> usize {
        let Some(p) = &self.shader.params else {
            return 0;
        };
        let align = p
            .members
            .iter()
            .map(|m| match m.ty {
                FieldType::F32(1) | FieldType::I32(1) | FieldType::U32(1) => 4,
                FieldType::F32(2) | FieldType::I32(2) | FieldType::U32(2) => 8,
                _ => 16,
            })
            .max()
            .unwrap_or(4);
        (p.size as usize).div_ceil(align) * align
    }
}

/// One scene material, resolved.
#[derive(Debug, Clone)]
pub struct MaterialEntry {
    pub name: String,
    /// Index into [`MaterialSet::surfaces`].
    pub surface: usize,
    /// Lighting model id: index into [`MaterialSet::lightings`].
    pub lighting: usize,
    /// The surface's parameter block (uniform layout), packed.
    pub surface_params: Vec<u8>,
    /// The lighting shader's parameter block, packed (empty without one).
    pub lighting_params: Vec<u8>,
    /// Material-level feature bits (alpha mode, double-sided, bound textures).
    pub features: u64,
    /// Per texture slot of the surface (its declaration order): the scene texture.
    pub textures: Vec<Option<usize>>,
    pub alpha_mode: AlphaMode,
    pub alpha_cutoff: f32,
    pub double_sided: bool,
}

/// Every material of a scene, with the distinct shaders they use.
#[derive(Debug, Clone, Default)]
pub struct MaterialSet {
    pub surfaces: Vec<ShaderInfo>,
    pub lightings: Vec<ShaderInfo>,
    pub materials: Vec<MaterialEntry>,
}

/// A material problem found while resolving a scene's materials.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{0}")]
pub struct MaterialError(pub String);

impl MaterialSet {
    /// Resolves every material of `scene`: loads (once) and checks each shader,
    /// checks and packs every parameter, and picks the material's features. All
    /// problems are reported together.
    pub fn build(scene: &Scene) -> Result<MaterialSet, MaterialError> {
        let mut set = MaterialSet::default();
        let mut errors: Vec<String> = Vec::new();
        for m in &scene.materials {
            match set.add(m, scene) {
                Ok(entry) => set.materials.push(entry),
                Err(e) => errors.extend(e),
            }
        }
        if errors.is_empty() {
            Ok(set)
        } else {
            errors.dedup();
            Err(MaterialError(errors.join("\n")))
        }
    }

    fn shader(
        list: &mut Vec<ShaderInfo>,
        kind: MaterialShaderKind,
        b: &ShaderBinding,
        material: &str,
    ) -> Result<usize, Vec<String>> {
        if let Some(i) = list
            .iter()
            .position(|s| s.name == b.shader && s.dir == b.dir)
        {
            return Ok(i);
        }
        let loaded = load_shader(kind, &b.shader, b.dir.as_deref()).map_err(|e| {
            vec![format!(
                "material `{material}`: {} shader `{}`:\n{e}",
                kind.name(),
                b.shader
            )]
        })?;
        list.push(ShaderInfo::new(&b.shader, b.dir.clone(), loaded));
        Ok(list.len() - 1)
    }

    fn add(&mut self, m: &Material, scene: &Scene) -> Result<MaterialEntry, Vec<String>> {
        let surface = Self::shader(
            &mut self.surfaces,
            MaterialShaderKind::Surface,
            &m.surface,
            &m.name,
        );
        let lighting = Self::shader(
            &mut self.lightings,
            MaterialShaderKind::Lighting,
            &m.lighting,
            &m.name,
        );
        let (surface, lighting) = match (surface, lighting) {
            (Ok(s), Ok(l)) => (s, l),
            (s, l) => {
                let mut e = s.err().unwrap_or_default();
                e.extend(l.err().unwrap_or_default());
                return Err(e);
            }
        };
        let mut errors = Vec::new();
        let s = &self.surfaces[surface];
        let l = &self.lightings[lighting];
        let surface_params = pack_params(s, &m.surface, &m.name, &mut errors);
        let lighting_params = pack_params(l, &m.lighting, &m.name, &mut errors);
        let (textures, texture_bits) = surface_textures(m, s, scene, &mut errors);
        let features = material_bits(m, s) | texture_bits;
        let _ = MaterialShaderKind::Surface;
        if !m.lighting.textures.is_empty() {
            errors.push(format!(
                "material `{}`: lighting shaders take no textures (the deferred light pass sees only the G-buffer)",
                m.name
            ));
        }
        // glTF bounds the cut-off below only: above 1, MASK discards everything.
        if m.alpha_cutoff.is_nan() || m.alpha_cutoff < 0.0 {
            errors.push(format!(
                "material `{}`: alpha cut-off {} is negative or not a number",
                m.name, m.alpha_cutoff
            ));
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        Ok(MaterialEntry {
            name: m.name.clone(),
            surface,
            lighting,
            surface_params,
            lighting_params,
            features,
            textures,
            alpha_mode: m.alpha_mode,
            alpha_cutoff: m.alpha_cutoff,
            double_sided: m.double_sided,
        })
    }

    /// One line per material: its shaders and the features its variant turns on.
    pub fn describe(&self) -> Vec<String> {
        self.materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let s = &self.surfaces[m.surface];
                let key = VariantKey {
                    surface: m.surface,
                    lighting: m.lighting,
                    features: m.features,
                };
                let names = key.feature_names(&s.flags);
                format!(
                    "{i:>3} {}: surface {} + lighting {} (model {}), variant [{}]",
                    m.name,
                    s.name,
                    self.lightings[m.lighting].name,
                    m.lighting,
                    names.join(" ")
                )
            })
            .collect()
    }
}

fn list_or_none<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let v: Vec<&str> = names.collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join(", ")
    }
}

/// Packs a shader's parameter block from the material's values (matched to field
/// names ignoring case, so the paper's `SPECULAR_POWER` sets `specular_power`),
/// the fields' `@default`s, or zero. Unknown names, wrong component counts and
/// values outside `@range` are errors.
/// Whether material binding `b` of surface `s` turns on a layer (the
/// `HAS_LAYERS` feature, layers.wgsl): its `clearcoat` or `transmission`
/// parameter, given or by default, above 0. Only such materials compile and run
/// the layers' shading (a material without them pays nothing for it).
fn has_layers(s: &ShaderInfo, b: &ShaderBinding) -> bool {
    let Some(p) = &s.shader.params else {
        return false;
    };
    p.members
        .iter()
        .filter(|m| {
            ["clearcoat", "transmission"]
                .iter()
                .any(|n| m.name.eq_ignore_ascii_case(n))
        })
        .any(|m| {
            let given = b
                .params
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(&m.name));
            let value = given.map(|(_, v)| v.clone()).or_else(|| m.default.clone());
            value.is_some_and(|v| v.iter().any(|x| *x > 0.0))
        })
}

/// The engine feature bits a material turns on: its alpha mode, double
/// sides, and layers of its surface shader `s`.
fn material_bits(m: &Material, s: &ShaderInfo) -> u64 {
    let mut features = 0u64;
    match m.alpha_mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask => features |= variant::engine_bit("ALPHA_MASK"),
        AlphaMode::Blend => features |= variant::engine_bit("ALPHA_BLEND"),
    }
    if m.double_sided {
        features |= variant::engine_bit("DOUBLE_SIDED");
    }
    if has_layers(s, &m.surface) {
        features |= variant::engine_bit("HAS_LAYERS");
    }
    features
}

/// The scene texture in each texture slot of surface shader `s`, and the
/// feature bits of the textures given; a texture the shader lacks or a
/// missing scene texture is an error.
fn surface_textures(
    m: &Material,
    s: &ShaderInfo,
    scene: &Scene,
    errors: &mut Vec<String>,
) -> (Vec<Option<usize>>, u64) {
    let mut features = 0u64;
    let mut textures = vec![None; s.shader.textures.len()];
    for (name, index) in &m.surface.textures {
        match s.shader.textures.iter().position(|t| &t.name == name) {
            Some(slot) => {
                if *index >= scene.textures.len() {
                    errors.push(format!(
                        "material `{}`: texture `{name}` refers to missing scene texture {index}",
                        m.name
                    ));
                    continue;
                }
                textures[slot] = Some(*index);
                features |= s.bit(&variant::texture_flag(name)).unwrap_or(0);
            }
            None => errors.push(format!(
                "material `{}`: surface shader `{}` has no texture `{name}` (its textures: {})",
                m.name,
                s.name,
                list_or_none(s.shader.textures.iter().map(|t| t.name.as_str()))
            )),
        }
    }
    (textures, features)
}

fn pack_params(
    s: &ShaderInfo,
    b: &ShaderBinding,
    material: &str,
    errors: &mut Vec<String>,
) -> Vec<u8> {
    let Some(p) = &s.shader.params else {
        for (name, _) in &b.params {
            errors.push(format!(
                "material `{material}`: shader `{}` takes no parameters (got `{name}`)",
                s.name
            ));
        }
        return Vec::new();
    };
    let mut bytes = vec![0u8; p.size as usize];
    for (name, _) in &b.params {
        if !p.members.iter().any(|m| m.name.eq_ignore_ascii_case(name)) {
            errors.push(format!(
                "material `{material}`: shader `{}` has no parameter `{name}` (its parameters: {})",
                s.name,
                list_or_none(p.members.iter().map(|m| m.name.as_str()))
            ));
        }
    }
    for m in &p.members {
        let given = b
            .params
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(&m.name))
            .map(|(_, v)| v.clone());
        match member_value(s, m, given.as_deref(), material) {
            Ok(value) => write_member(&mut bytes, m, &value),
            Err(e) => errors.push(e),
        }
    }
    bytes
}

/// The value of parameter `m` of shader `s`: the one given, else its default,
/// else zeros; checked for its component count, finite values, and (when
/// given) its range.
fn member_value(
    s: &ShaderInfo,
    m: &crate::shader::reflect::UniformMember,
    given: Option<&[f64]>,
    material: &str,
) -> Result<Vec<f64>, String> {
    let n = m.ty.components();
    let value = match (given, &m.default) {
        (Some(v), _) => v.to_vec(),
        (None, Some(d)) => d.clone(),
        (None, None) => vec![0.0; n],
    };
    if value.len() != n {
        return Err(format!(
            "material `{material}`: `{}` of shader `{}` is {} ({n} value{}), got {} value{}",
            m.name,
            s.name,
            m.ty.wgsl(),
            if n == 1 { "" } else { "s" },
            value.len(),
            if value.len() == 1 { "" } else { "s" }
        ));
    }
    if let Some(bad) = value.iter().find(|x| !x.is_finite()) {
        return Err(format!(
            "material `{material}`: `{}` = {bad} is not finite",
            m.name
        ));
    }
    if given.is_some() {
        if let Some((lo, hi)) = m.range {
            if let Some(bad) = value.iter().find(|x| **x < lo || **x > hi) {
                return Err(format!(
                    "material `{material}`: `{}` = {bad} is outside its range {lo}..{hi}",
                    m.name
                ));
            }
        }
    }
    Ok(value)
}

/// Writes `value` at parameter `m`'s offset in `bytes`, as its type's words.
fn write_member(bytes: &mut [u8], m: &crate::shader::reflect::UniformMember, value: &[f64]) {
    for (i, x) in value.iter().enumerate() {
        let at = m.offset as usize + i * 4;
        let word: [u8; 4] = match m.ty {
            FieldType::I32(_) => (*x as i32).to_le_bytes(),
            FieldType::U32(_) => (x.max(0.0) as u32).to_le_bytes(),
            _ => (*x as f32).to_le_bytes(),
        };
        if at + 4 <= bytes.len() {
            bytes[at..at + 4].copy_from_slice(&word);
        }
    }
}
