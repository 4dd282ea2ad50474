//! Embeds `effects/*.fx`, `shaders/*.wgsl`, the material shaders
//! (`shaders/materials/*.wgsl` and `shaders/materials/lib/*.wgsl`) and
//! `materials/*.fx` into the library so `fxrun glow` works from any directory.
//! Missing or empty folders give empty tables.
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

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let mut out = String::new();
    table(
        &mut out,
        "EMBEDDED_EFFECTS",
        "`effects/`",
        &files(&root, "effects", "fx", ""),
    );
    table(
        &mut out,
        "EMBEDDED_SHADERS",
        "`shaders/`",
        &files(&root, "shaders", "wgsl", ""),
    );
    let mut materials = files(&root, "shaders/materials", "wgsl", "");
    materials.extend(files(&root, "shaders/materials/lib", "wgsl", "lib/"));
    table(
        &mut out,
        "EMBEDDED_MATERIAL_SHADERS",
        "`shaders/materials/` and `shaders/materials/lib/` (names like `standard.wgsl`, `lib/brdf.wgsl`)",
        &materials,
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
