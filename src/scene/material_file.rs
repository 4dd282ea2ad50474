//! Materials written in the EFFECT language (`MATERIAL.name = { SURFACE = ...
//! LIGHTING = ... }`, see `docs/materials.md`) turned into scene [`Material`]s:
//! texture files loaded (relative to the material file, confined to its folder),
//! and every setting checked against its shader with the setting's span.

use crate::scene::model::{AlphaMode, Material, ShaderBinding, TextureImage};
use crate::script::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::script::material::{AlphaSpec, MaterialDef, MaterialShader, MaterialValue};
use crate::shader::material::{self as shader_material, MaterialShaderKind};
use std::path::{Path, PathBuf};

/// Largest texture file a material may name.
pub const MAX_TEXTURE_FILE_BYTES: u64 = 256 << 20;

/// Materials parsed from one file, with the textures they load.
#[derive(Debug, Clone, Default)]
pub struct MaterialFile {
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
}

/// Parses and checks every `MATERIAL` of `text` (shown as `shown` in messages;
/// texture paths and user shaders are looked up under `dir`). Texture indices in
/// the result count from `first_texture` (where the caller will append
/// [`MaterialFile::textures`] to its scene). All problems come back together as a
/// rendered report.
pub fn load_materials(
    shown: &str,
    text: &str,
    dir: Option<&Path>,
    first_texture: usize,
) -> Result<MaterialFile, String> {
    let mut sources = SourceMap::new();
    let file = sources.add(shown, text);
    let mut diags = Diagnostics::default();
    let module = crate::script::parse_module(&sources, file, &mut diags);
    if !module.effects.is_empty() {
        log::debug!("{shown}: effects in a material file are ignored");
    }
    let mut loader = Loader {
        dir,
        first_texture,
        textures: Vec::new(),
        shaders: Shaders::new(),
        sources,
        diags,
    };
    let materials = module
        .materials
        .iter()
        .filter_map(|def| loader.material(def))
        .collect();
    if loader.diags.has_errors() {
        return Err(loader.diags.render(&loader.sources));
    }
    for d in &loader.diags.list {
        log::warn!("{}", d.render(&loader.sources));
    }
    Ok(MaterialFile {
        materials,
        textures: loader.textures,
    })
}

/// A procedural texture named `builtin:NAME` (so built-in materials and tests
/// need no files), 256×256: `checker` (8×8 squares of sRGB 200 / 60 grey),
/// `bricks` (colour), `bumps` (a tangent-space normal map of 8×8 round bumps).
pub fn builtin_texture(name: &str) -> Option<TextureImage> {
    let (w, h) = (256u32, 256u32);
    let mut rgba8 = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let v: [u8; 3] = match name {
                "bumps" => {
                    // height = cos bumps of period 32 px (y down the image)
                    let k = std::f32::consts::TAU / 32.0;
                    let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
                    let dx = -0.6 * (k * fx).sin() * (k * fy).cos();
                    let dy = -0.6 * (k * fx).cos() * (k * fy).sin();
                    // +Y of a normal map is image up: -dh/d(up) = +dh/dy
                    let n = glam::Vec3::new(-dx, dy, 1.0).normalize();
                    let e = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
                    [e(n.x), e(n.y), e(n.z)]
                }
                "checker" => {
                    if ((x / 32) + (y / 32)) % 2 == 0 {
                        [200, 200, 200]
                    } else {
                        [60, 60, 60]
                    }
                }
                "bricks" => {
                    let row = y / 32;
                    let shift = if row % 2 == 0 { 0 } else { 32 };
                    let mortar = y % 32 < 3 || (x + shift) % 64 < 3;
                    if mortar {
                        [190, 185, 175]
                    } else {
                        let n = ((x * 7 + y * 13) % 23) as u8;
                        [150 + n, 60 + n / 2, 45]
                    }
                }
                _ => return None,
            };
            rgba8.extend_from_slice(&[v[0], v[1], v[2], 255]);
        }
    }
    Some(TextureImage {
        name: format!("builtin:{name}"),
        width: w,
        height: h,
        rgba8,
    })
}

/// Resolves `path` under `dir` without leaving it (no `..`, no absolute paths,
/// symlinks followed and checked). The refused path's contents are never read.
fn confined(dir: Option<&Path>, path: &str) -> Result<PathBuf, String> {
    let rel = Path::new(path);
    if rel.is_absolute()
        || rel.components().any(|c| {
            matches!(
                c,
                std::path::Component::ParentDir | std::path::Component::Prefix(_)
            )
        })
    {
        return Err(format!(
            "`{path}` must be a relative path inside the material file's folder"
        ));
    }
    // `dir` is "" for a material file given by its bare name: the current folder.
    let base = dir
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let full = base.join(rel);
    let canon_base = base
        .canonicalize()
        .map_err(|e| format!("{}: {e}", base.display()))?;
    let canon = full
        .canonicalize()
        .map_err(|e| format!("{}: {e}", full.display()))?;
    if !canon.starts_with(&canon_base) {
        return Err(format!(
            "`{path}` resolves outside the material file's folder (a link?)"
        ));
    }
    let meta = std::fs::metadata(&canon).map_err(|e| format!("{}: {e}", full.display()))?;
    if !meta.is_file() {
        return Err(format!("{}: not a regular file", full.display()));
    }
    if meta.len() > MAX_TEXTURE_FILE_BYTES {
        return Err(format!(
            "{}: {} bytes, more than the {} MiB a texture may have",
            full.display(),
            meta.len(),
            MAX_TEXTURE_FILE_BYTES >> 20
        ));
    }
    Ok(canon)
}

fn load_texture(dir: Option<&Path>, path: &str) -> Result<TextureImage, String> {
    if let Some(name) = path.strip_prefix("builtin:") {
        return builtin_texture(name)
            .ok_or_else(|| {
                format!(
                    "unknown built-in texture `{path}` (builtin:checker, builtin:bricks, builtin:bumps)"
                )
            });
    }
    let full = confined(dir, path)?;
    let img = crate::io::load_image(&full, &crate::io::LoadOptions::default())
        .map_err(|e| e.to_string())?;
    Ok(TextureImage {
        name: path.to_string(),
        width: img.width,
        height: img.height,
        // 8-bit files as stored; float files encoded to sRGB-like 8 bits.
        rgba8: img.pixels.to_u8_srgb(false),
    })
}

/// The shaders a file's materials use, loaded once each (the built-in `standard`
/// serves most materials; checking it is most of the time a file takes).
type Shaders =
    std::collections::HashMap<(MaterialShaderKind, String), shader_material::MaterialShader>;

/// What the materials of one file share while they are checked: where the file
/// is, the textures loaded so far, the shaders loaded once each, the sources (the
/// shaders' files are added) and the problems found.
struct Loader<'d> {
    dir: Option<&'d Path>,
    first_texture: usize,
    textures: Vec<TextureImage>,
    shaders: Shaders,
    sources: SourceMap,
    diags: Diagnostics,
}

impl Loader<'_> {
    fn material(&mut self, def: &MaterialDef) -> Option<Material> {
        let surface = self.binding(&def.surface, MaterialShaderKind::Surface);
        let lighting = self.binding(&def.lighting, MaterialShaderKind::Lighting);
        let (surface, lighting) = (surface?, lighting?);
        let mut m = Material::new(&def.name.node, surface, lighting);
        m.alpha_mode = match def.alpha.as_ref().map(|a| a.node) {
            None | Some(AlphaSpec::Opaque) => AlphaMode::Opaque,
            Some(AlphaSpec::Mask) => AlphaMode::Mask,
            Some(AlphaSpec::Blend) => AlphaMode::Blend,
        };
        if let Some(c) = &def.alpha_cutoff {
            m.alpha_cutoff = c.node as f32;
        }
        if let Some(d) = &def.double_sided {
            m.double_sided = d.node;
        }
        Some(m)
    }

    fn binding(
        &mut self,
        use_: &MaterialShader,
        kind: MaterialShaderKind,
    ) -> Option<ShaderBinding> {
        let key = (kind, use_.shader.node.clone());
        if !self.shaders.contains_key(&key) {
            let s = load_binding_shader(use_, kind, self.dir, &mut self.sources, &mut self.diags)?;
            self.shaders.insert(key.clone(), s);
        }
        let shader = &self.shaders[&key];
        bind_settings(
            use_,
            kind,
            shader,
            self.dir,
            self.first_texture,
            &mut self.textures,
            &mut self.diags,
        )
    }
}

/// Finds and checks the shader `use_` names; problems go to `diags`.
fn load_binding_shader(
    use_: &MaterialShader,
    kind: MaterialShaderKind,
    dir: Option<&Path>,
    sources: &mut SourceMap,
    diags: &mut Diagnostics,
) -> Option<shader_material::MaterialShader> {
    let name = &use_.shader.node;
    let Some(file) = shader_material::find_material_shader(name, dir) else {
        diags.push(
            Diagnostic::error(format!("unknown {} shader `{name}`", kind.name()))
                .at(use_.shader.span, "no such shader")
                .note(format!(
                    "built-in shaders: {}; a user's shader is `{name}.wgsl` next to the material file",
                    shader_material::builtin_material_shaders().join(", ")
                )),
        );
        return None;
    };
    let shader = match shader_material::load_material_shader(kind, name, file, sources) {
        Ok(s) => s,
        Err(errors) => {
            // The shader's own diagnostics point into its file; this one says
            // which material uses it.
            diags.push(
                Diagnostic::error(format!(
                    "{} shader `{name}` has {} error{}",
                    kind.name(),
                    errors.len(),
                    if errors.len() == 1 { "" } else { "s" }
                ))
                .at(use_.shader.span, "used here"),
            );
            for d in errors {
                diags.push(d);
            }
            return None;
        }
    };
    Some(shader)
}

/// Checks the values of parameter `p`: as many as its type has components,
/// each inside its range; false (with an error at `span`) when not.
fn check_param_values(
    p: &crate::shader::reflect::UniformMember,
    v: &[f64],
    span: crate::script::diag::Span,
    diags: &mut Diagnostics,
) -> bool {
    let n = p.ty.components();
    if v.len() != n {
        diags.push(
            Diagnostic::error(format!(
                "`{}` is {} ({n} value{}), got {} value{}",
                p.name,
                p.ty.wgsl(),
                if n == 1 { "" } else { "s" },
                v.len(),
                if v.len() == 1 { "" } else { "s" }
            ))
            .at(span, "wrong number of values"),
        );
        return false;
    }
    if let Some((lo, hi)) = p.range {
        if let Some(bad) = v.iter().find(|x| **x < lo || **x > hi) {
            diags.push(
                Diagnostic::error(format!(
                    "`{}` = {bad} is outside its range {lo}..{hi}",
                    p.name
                ))
                .at(span, "out of range"),
            );
            return false;
        }
    }
    true
}

/// The error of a setting `key` that `shader` (named `name`) does not take,
/// listing the settings it takes.
fn unknown_setting(
    shader: &shader_material::MaterialShader,
    kind: MaterialShaderKind,
    name: &str,
    key: &crate::script::diag::Spanned<String>,
) -> Diagnostic {
    let mut known: Vec<&str> = shader
        .params
        .iter()
        .flat_map(|p| p.members.iter().map(|m| m.name.as_str()))
        .collect();
    known.extend(shader.textures.iter().map(|t| t.name.as_str()));
    Diagnostic::error(format!(
        "{} shader `{name}` has no setting `{}`",
        kind.name(),
        key.node
    ))
    .at(key.span, "unknown setting")
    .note(if known.is_empty() {
        "this shader takes no settings".to_string()
    } else {
        format!("its settings: {}", known.join(", "))
    })
}

/// The binding of `use_` to its loaded `shader`: every setting checked against the
/// shader's parameters and textures (textures loaded).
fn bind_settings(
    use_: &MaterialShader,
    kind: MaterialShaderKind,
    shader: &shader_material::MaterialShader,
    dir: Option<&Path>,
    first_texture: usize,
    textures: &mut Vec<TextureImage>,
    diags: &mut Diagnostics,
) -> Option<ShaderBinding> {
    let name = &use_.shader.node;
    let mut b = ShaderBinding {
        shader: name.clone(),
        dir: dir.map(Path::to_path_buf),
        ..Default::default()
    };
    let mut ok = true;
    for s in &use_.settings {
        let key = &s.name.node;
        let param = shader
            .params
            .as_ref()
            .and_then(|p| p.members.iter().find(|m| m.name.eq_ignore_ascii_case(key)));
        let texture = shader
            .textures
            .iter()
            .find(|t| t.name.eq_ignore_ascii_case(key));
        match (&s.value.node, param, texture) {
            (MaterialValue::Numbers(v), Some(p), _) => {
                ok &= check_param_values(p, v, s.value.span, diags);
                b.params.push((p.name.clone(), v.clone()));
            }
            (MaterialValue::Text(path), _, Some(t)) => match load_texture(dir, path.as_str()) {
                Ok(img) => {
                    textures.push(img);
                    b.textures
                        .push((t.name.clone(), first_texture + textures.len() - 1));
                }
                Err(e) => {
                    diags.push(
                        Diagnostic::error(format!("texture `{}`: {e}", t.name))
                            .at(s.value.span, "cannot load this texture"),
                    );
                    ok = false;
                }
            },
            (MaterialValue::Text(_), Some(p), None) => {
                diags.push(
                    Diagnostic::error(format!(
                        "`{}` is a parameter ({}), not a texture",
                        p.name,
                        p.ty.wgsl()
                    ))
                    .at(s.value.span, "expected a number or a tuple"),
                );
                ok = false;
            }
            (MaterialValue::Numbers(_), None, Some(t)) => {
                diags.push(
                    Diagnostic::error(format!("`{}` is a texture", t.name))
                        .at(s.value.span, "expected a file path in quotes"),
                );
                ok = false;
            }
            (_, None, None) => {
                diags.push(unknown_setting(shader, kind, name, &s.name));
                ok = false;
            }
        }
    }
    ok.then_some(b)
}

/// Where a material definition applies: `--material SCENE_NAME=DEFINITION` pairs
/// (`*` for every scene material), and definitions whose name equals a scene
/// material's name.
pub fn apply_materials(
    scene: &mut crate::scene::Scene,
    file: MaterialFile,
    mapping: &[(String, String)],
) -> Result<Vec<String>, String> {
    scene.textures.extend(file.textures);
    let mut replaced = Vec::new();
    for (target, def) in mapping {
        let Some(m) = file.materials.iter().find(|m| &m.name == def) else {
            return Err(format!(
                "--material {target}={def}: no MATERIAL.{def} in the material file (defined: {})",
                file.materials
                    .iter()
                    .map(|m| m.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        };
        let mut hit = false;
        for sm in scene.materials.iter_mut() {
            if target == "*" || &sm.name == target {
                let keep = sm.name.clone();
                *sm = m.clone();
                sm.name = keep;
                replaced.push(sm.name.clone());
                hit = true;
            }
        }
        if !hit {
            return Err(format!(
                "--material {target}={def}: the scene has no material `{target}` (materials: {})",
                scene
                    .materials
                    .iter()
                    .map(|m| m.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    for m in &file.materials {
        for sm in scene.materials.iter_mut() {
            if sm.name == m.name && !mapping.iter().any(|(t, _)| t == "*" || *t == sm.name) {
                *sm = m.clone();
                replaced.push(sm.name.clone());
            }
        }
    }
    Ok(replaced)
}
