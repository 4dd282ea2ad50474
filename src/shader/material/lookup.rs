//! Finding a material shader: the user's folder first (confined like includes),
//! then the built-in tree embedded in the binary.

use crate::graph::library::EMBEDDED_MATERIAL_SHADERS;
use crate::shader::include::{self, RealFs};
use crate::shader::ShaderFile;
use std::path::Path;

/// The built-in material tree: `standard.wgsl`, `lib/brdf.wgsl`, ...
pub fn embedded_material_shader(rel: &str) -> Option<&'static str> {
    EMBEDDED_MATERIAL_SHADERS
        .iter()
        .find(|(n, _)| *n == rel)
        .map(|(_, t)| *t)
}

/// The built-in material shaders by name (`standard`, `phong`, ...), without the
/// library files.
pub fn builtin_material_shaders() -> Vec<&'static str> {
    EMBEDDED_MATERIAL_SHADERS
        .iter()
        .filter(|(n, _)| !n.contains('/'))
        .filter_map(|(n, _)| n.strip_suffix(".wgsl"))
        .collect()
}

/// How built-in material shaders are named in messages (then their path).
pub(super) const BUILTIN_PREFIX: &str = "<builtin>/shaders/materials/";

/// Find a material shader: `name` (`phong`, `phong.wgsl`, `sub/mine.wgsl`) under
/// `dir` first (confined like includes: no `..`, no absolute path, symlinks must
/// stay under `dir`, a regular file of at most 1 MiB), then the built-in ones.
pub fn find_material_shader(name: &str, dir: Option<&Path>) -> Option<ShaderFile> {
    let file = if name.ends_with(".wgsl") {
        name.to_string()
    } else {
        format!("{name}.wgsl")
    };
    let parts = include::check_relative(&file).ok()?;
    // The folder of a bare file name (`mine.fx`) is "", which cannot be made
    // canonical: it is the current folder.
    let dir = dir.map(|d| {
        if d.as_os_str().is_empty() {
            Path::new(".")
        } else {
            d
        }
    });
    if let Some(dir) = dir {
        if let Ok(canon_dir) = std::fs::canonicalize(dir) {
            if let Ok(Some((canon, text))) = include::read_confined(&canon_dir, &parts, &RealFs) {
                return Some(ShaderFile {
                    shown: dir.join(&file).display().to_string(),
                    text,
                    path: Some(canon),
                });
            }
        }
    }
    let rel = parts.join("/");
    if rel.starts_with("lib/") {
        return None;
    }
    embedded_material_shader(&rel).map(|t| ShaderFile {
        shown: format!("{BUILTIN_PREFIX}{rel}"),
        text: t.to_string(),
        path: None,
    })
}
