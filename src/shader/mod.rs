//! Shaders: finding a pass's WGSL file, `#ifdef` preprocessing, naga reflection,
//! checking the script's bindings against the shader's declarations, and the
//! uniform layout with its standard values (`uniforms`). No GPU code.
//!
//! The conventions are documented in `docs/shaders.md`.

pub mod compute;
pub mod features;
pub mod include;
pub mod interface;
pub mod load;
pub mod material;
pub mod preprocess;
pub mod reflect;
pub mod rename;
pub mod uniforms;
pub mod wgsl_names;

pub use features::{convert_features, feature_flags_used, FeatureMode};
pub use load::{
    check_references, compile_all, load_plan_shaders, load_plan_shaders_with, pass_parameters,
    preload_graph_shaders, LoadedShader, PassParamInfo, ShaderCache, GENERATED_FROM,
};
pub use material::{
    find_material_shader, load_material_shader, MaterialParams, MaterialSampler, MaterialShader,
    MaterialShaderKind, MaterialTexture, MATERIAL_INTERFACE,
};
pub use preprocess::preprocess;
pub use reflect::{
    check_member_value, reflect, ComputeNative, Reflection, StdValue, StorageOutput, UniformField,
    UniformLayout, UniformMember, UniformSource, ValueMismatch,
};
pub use rename::prefix_module_names;

use crate::graph::library::embedded_shader;
use std::path::{Path, PathBuf};

/// The fullscreen vertex stage every pass uses (the library's, not the user's).
pub const FULLSCREEN_VS: &str = r#"
struct FxVertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// One triangle covering the viewport; uv is (0,0) at the top-left texel corner.
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> FxVertexOut {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: FxVertexOut;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}
"#;

/// A shader file's text and the name it is shown under in diagnostics.
#[derive(Debug, Clone)]
pub struct ShaderFile {
    pub shown: String,
    pub text: String,
    pub path: Option<PathBuf>,
}

/// Find `NAME.wgsl`: next to the effect file (and in its `shaders/` and
/// `../shaders/`), then in the extra folders; for a built-in effect, then in
/// `./shaders/` (files on disk override the embedded library); then the
/// embedded library.
pub fn find_shader(
    name: &str,
    effect_dir: Option<&Path>,
    extra_dirs: &[PathBuf],
) -> Option<ShaderFile> {
    let file = format!("{name}.wgsl");
    let mut dirs: Vec<PathBuf> = Vec::new();
    if let Some(d) = effect_dir {
        dirs.push(d.to_path_buf());
        dirs.push(d.join("shaders"));
        dirs.push(d.join("..").join("shaders"));
    }
    dirs.extend(extra_dirs.iter().cloned());
    if effect_dir.is_none() {
        dirs.push(PathBuf::from("shaders"));
    }
    for d in dirs {
        let p = d.join(&file);
        if let Ok(text) = std::fs::read_to_string(&p) {
            return Some(ShaderFile {
                shown: p.display().to_string(),
                text,
                path: Some(p),
            });
        }
    }
    embedded_shader(&file).map(|(rel, t)| ShaderFile {
        shown: format!("<builtin>/shaders/{rel}"),
        text: t.to_string(),
        path: None,
    })
}
