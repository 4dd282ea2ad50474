//! Embeds the library into the binary so `fxrun glow` works from any directory:
//!
//! - `effects/*.fx`: the built-in effects;
//! - `shaders/effects/<effect>/*.wgsl` and `shaders/engine/*.wgsl`: the pass
//!   shaders, found by file name (`SHADER.blurX` is `blurX.wgsl`), so every name
//!   must be unique across those folders (checked here);
//! - `shaders/lib/*.wgsl`: the shared WGSL library (`#include "lib/NAME.wgsl"`);
//! - `shaders/materials/*.wgsl`: the built-in material shaders;
//! - `materials/*.fx`: the built-in material files.
//!
//! The renderer's and the viewer's own shaders (`shaders/render/`, `shaders/view/`)
//! are compiled in by `include_str!` where they are used. Missing or empty folders
//! give empty tables.
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The files of `dir` with extension `ext`, sorted, named `prefix` + file name.
fn files(root: &Path, dir: &str, ext: &str, prefix: &str) -> Vec<(String, PathBuf)> {
    let path = root.join(dir);
    println!("cargo:rerun-if-changed={}", path.display());
    let mut files: Vec<PathBuf> = std::fs::read_dir(&path)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.is_file() && p.extension().and_then(|e| e.to_str()) == Some(ext));
    files.sort();
    files
        .into_iter()
        .filter_map(|f| {
            let name = f.file_name()?.to_str()?.to_string();
            Some((format!("{prefix}{name}"), f))
        })
        .collect()
}

/// The sub-folders of `dir`, sorted, as paths relative to the root.
fn subdirs(root: &Path, dir: &str) -> Vec<String> {
    let path = root.join(dir);
    println!("cargo:rerun-if-changed={}", path.display());
    let mut out: Vec<String> = std::fs::read_dir(&path)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .filter(|e| e.path().is_dir())
                .filter_map(|e| Some(format!("{dir}/{}", e.file_name().to_str()?)))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

fn table(out: &mut String, konst: &str, what: &str, files: &[(String, PathBuf)]) {
    writeln!(
        out,
        "/// Files of {what} embedded at build time: (name, contents)."
    )
    .unwrap();
    writeln!(out, "pub static {konst}: &[(&str, &str)] = &[").unwrap();
    for (name, f) in files {
        println!("cargo:rerun-if-changed={}", f.display());
        writeln!(
            out,
            "    ({name:?}, include_str!({:?})),",
            f.display().to_string()
        )
        .unwrap();
    }
    writeln!(out, "];").unwrap();
}

/// The pass shaders: (file name, path under `shaders/`, contents), names unique.
fn pass_shader_table(out: &mut String, root: &Path) {
    let mut dirs = subdirs(root, "shaders/effects");
    dirs.push("shaders/engine".to_string());
    let mut all: Vec<(String, String, PathBuf)> = Vec::new();
    for d in &dirs {
        let rel_dir = d.trim_start_matches("shaders/");
        for (name, f) in files(root, d, "wgsl", "") {
            if let Some((_, other, _)) = all.iter().find(|(n, _, _)| *n == name) {
                panic!("two pass shaders are named {name}: shaders/{other} and {d}/{name}");
            }
            all.push((name.clone(), format!("{rel_dir}/{name}"), f));
        }
    }
    all.sort();
    writeln!(
        out,
        "/// Pass shaders of `shaders/effects/*/` and `shaders/engine/` embedded at build\n\
         /// time: (file name, path under `shaders/`, contents)."
    )
    .unwrap();
    writeln!(
        out,
        "pub static EMBEDDED_SHADERS: &[(&str, &str, &str)] = &["
    )
    .unwrap();
    for (name, rel, f) in &all {
        println!("cargo:rerun-if-changed={}", f.display());
        writeln!(
            out,
            "    ({name:?}, {rel:?}, include_str!({:?})),",
            f.display().to_string()
        )
        .unwrap();
    }
    writeln!(out, "];").unwrap();
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let mut out = String::new();
    table(
        &mut out,
        "EMBEDDED_EFFECTS",
        "`effects/`",
        &files(&root, "effects", "fx", ""),
    );
    pass_shader_table(&mut out, &root);
    table(
        &mut out,
        "EMBEDDED_SHADER_LIBRARY",
        "`shaders/lib/` (names like `lib/brdf.wgsl`)",
        &files(&root, "shaders/lib", "wgsl", "lib/"),
    );
    table(
        &mut out,
        "EMBEDDED_MATERIAL_SHADERS",
        "`shaders/materials/` (names like `standard.wgsl`)",
        &files(&root, "shaders/materials", "wgsl", ""),
    );
    table(
        &mut out,
        "EMBEDDED_MATERIALS",
        "`materials/`",
        &files(&root, "materials", "fx", ""),
    );
    let dest = Path::new(&std::env::var("OUT_DIR").unwrap()).join("embedded.rs");
    std::fs::write(dest, out).unwrap();
}
