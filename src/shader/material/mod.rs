//! Material shaders: finding, assembling (`#include`), checking and reflecting the
//! two small WGSL functions a material is made of.
//!
//! - A *surface shader* defines `fn surface(in: SurfaceInput) -> SurfaceOutput`,
//!   optionally `struct SurfaceParams { ... }` (fields annotated like effect
//!   parameters) bound once as `@group(2) @binding(N) var<uniform> NAME: SurfaceParams;`,
//!   textures `@group(2) @binding(N) var NAME: texture_2d<f32>; // [@srgb] text` and
//!   samplers `@group(2) @binding(N) var NAME: sampler;`. Bindings are in group 2
//!   and below 16 (16 and up are the engine's). It may test the feature flags
//!   `HAS_<TEXTURE>` and [`ENGINE_FLAGS`](features::ENGINE_FLAGS) with `#ifdef`/`#ifndef`
//!   (see [`super::features`]).
//! - A *lighting shader* defines `fn lighting(in: LightingInput) -> LightingOutput`
//!   or `fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput`
//!   with an annotated `struct LightingParams`, and optionally `fn
//!   environment(in: EnvironmentInput[, params: LightingParams]) -> LightingOutput`
//!   (its own image-based lighting). It declares no resources.
//!
//! Both see the engine's types ([`MATERIAL_INTERFACE`]); names starting with `fx_`
//! or `FX_` are the engine's. The engine generates the entry points.
//!
//! The files of this folder:
//! - `lookup.rs`: finding a shader (the user's folder, then the built-in tree);
//! - `check.rs`: the checks of the text, and compiling and validating it in every
//!   way the renderer compiles it, with naga's errors mapped to the user's files;
//! - `reflect.rs`: its function signature and params, read from the validated
//!   module;
//! - `resources.rs`: its resources (textures, samplers, the params uniform), their
//!   bindings and feature flags;
//! - `tests.rs`: the unit tests.

use super::features::{self, convert_features, FeatureMode};
use super::include::{assemble, Assembly, IncludeFs, IncludeOrigin, RealFs};
use super::preprocess::{preprocess, PreprocessError};
use super::reflect::UniformMember;
use super::rename::prefix_module_names;
use super::ShaderFile;
use crate::script::{Diagnostic, FileId, SourceMap, Span};

mod check;
mod lookup;
mod reflect;
mod resources;

#[cfg(test)]
mod tests;

pub use crate::shader::wgsl_names::sanitize;
use check::Checker;
use lookup::BUILTIN_PREFIX;
pub use lookup::{builtin_material_shaders, embedded_material_shader, find_material_shader};

/// The engine's types every material shader sees (appended to it).
pub const MATERIAL_INTERFACE: &str =
    include_str!("../../../shaders/materials/interface/material_interface.wgsl");
/// How [`MATERIAL_INTERFACE`] is named in messages.
pub const MATERIAL_INTERFACE_SHOWN: &str = "<builtin>/material_interface.wgsl";
/// The names [`MATERIAL_INTERFACE`] declares (kept when renaming lighting shaders).
pub const INTERFACE_NAMES: &[&str] = &[
    "SurfaceInput",
    "SurfaceOutput",
    "LightingInput",
    "LightingOutput",
    "EnvironmentInput",
    "FX_PI",
];
/// The bind group of a surface shader's resources.
pub const MATERIAL_GROUP: u32 = 2;
/// Surface shader bindings are below this; the engine's start here.
pub const FIRST_ENGINE_BINDING: u32 = 16;
/// The declaration the feature test of [`FeatureMode::Branch`] reads in the checks
/// (`fx_features` bit `i` is the shader's `i`-th flag of [`MaterialShader::flags`]).
pub const BRANCH_FEATURES_DECL: &str =
    "@group(2) @binding(16) var<uniform> fx_features: vec4<u32>;\n";

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MaterialShaderKind {
    Surface,
    Lighting,
}

impl MaterialShaderKind {
    /// "surface" or "lighting": the function a shader of this kind defines, and
    /// the word messages use.
    pub fn name(self) -> &'static str {
        match self {
            MaterialShaderKind::Surface => "surface",
            MaterialShaderKind::Lighting => "lighting",
        }
    }
    fn params_struct(self) -> &'static str {
        match self {
            MaterialShaderKind::Surface => "SurfaceParams",
            MaterialShaderKind::Lighting => "LightingParams",
        }
    }
}

/// The `SurfaceParams` / `LightingParams` struct.
#[derive(Debug, Clone)]
pub struct MaterialParams {
    pub struct_name: String,
    /// Size in bytes (WGSL layout rules).
    pub size: u32,
    pub members: Vec<UniformMember>,
    /// The struct declaration.
    pub span: Span,
}

/// A `texture_2d<f32>` of a surface shader.
#[derive(Debug, Clone)]
pub struct MaterialTexture {
    pub name: String,
    pub binding: u32,
    /// `// @srgb`: colour data, sampled through an sRGB view.
    pub srgb: bool,
    /// Its feature flag, `HAS_<NAME>`.
    pub flag: String,
    pub description: String,
    pub span: Span,
}

/// A `sampler` of a surface shader (the engine binds a linear, repeat, mipmapped one).
#[derive(Debug, Clone)]
pub struct MaterialSampler {
    pub name: String,
    pub binding: u32,
    pub span: Span,
}

/// A checked material shader.
#[derive(Debug, Clone)]
pub struct MaterialShader {
    /// The name it was asked for (`standard`).
    pub name: String,
    pub kind: MaterialShaderKind,
    /// How its file is named in messages.
    pub label: String,
    /// Its file in the [`SourceMap`].
    pub file: FileId,
    /// The file with its includes appended (directives blanked), without the
    /// interface and not preprocessed; spans map back through `assembly`.
    pub text: String,
    pub assembly: Assembly,
    /// Surface: every flag a pipeline may set ([`ENGINE_FLAGS`](features::ENGINE_FLAGS), then `HAS_<TEXTURE>`
    /// per texture in binding order); bit `i` of [`FeatureMode::Branch`]'s
    /// feature word is `flags[i]`. Empty for lighting shaders.
    pub flags: Vec<String>,
    /// The flags the text tests (a subset of `flags`), sorted.
    pub features: Vec<String>,
    pub params: Option<MaterialParams>,
    /// Surface: the binding and variable name of the `SurfaceParams` uniform.
    pub params_binding: Option<u32>,
    pub params_var: Option<String>,
    pub textures: Vec<MaterialTexture>,
    pub samplers: Vec<MaterialSampler>,
    /// Lighting: `fn lighting(in: LightingInput, params: LightingParams)`.
    pub lighting_takes_params: bool,
    /// Lighting: the optional `fn environment(in: EnvironmentInput[, params:
    /// LightingParams]) -> LightingOutput` that replaces the engine's environment
    /// term: `Some(takes params)`.
    pub environment: Option<bool>,
}

impl MaterialShader {
    /// The surface shader's WGSL for one way of compiling its feature flags
    /// (without the interface, which the caller appends once per module):
    /// - `Preprocess`: the flags in `enabled` are defined;
    /// - `Override`: `override FLAG: bool = false;` for every flag of [`Self::flags`];
    /// - `Branch`: `branch_cond(flag)` is the run-time test of a flag.
    ///
    /// Lighting shaders have no flags: every mode gives the preprocessed text.
    pub fn wgsl(
        &self,
        mode: FeatureMode,
        enabled: &[&str],
        branch_cond: &dyn Fn(&str) -> String,
    ) -> Result<String, PreprocessError> {
        let flags: Vec<&str> = self.flags.iter().map(String::as_str).collect();
        let converted = match mode {
            FeatureMode::Preprocess => {
                let defs: Vec<(String, i64)> = enabled
                    .iter()
                    .filter(|f| flags.contains(f))
                    .map(|f| (f.to_string(), 1))
                    .collect();
                return preprocess(&self.text, &defs).map(|r| r.0);
            }
            FeatureMode::Override => features::to_override_mode(&self.text, &flags)?,
            FeatureMode::Branch => convert_features(&self.text, &flags, branch_cond)?,
        };
        preprocess(&converted, &[]).map(|r| r.0)
    }

    /// A lighting shader's WGSL with its module-scope names prefixed (`lm0_` gives
    /// `lm0_lighting`, `lm0_LightingParams`), to sit beside other lighting shaders
    /// and the interface in one module.
    pub fn lighting_wgsl(&self, prefix: &str) -> Result<String, String> {
        let (text, _) = preprocess(&self.text, &[]).map_err(|e| e.message)?;
        prefix_module_names(&text, prefix, INTERFACE_NAMES)
    }
}

/// Load and check a material shader from disk or the built-in library (includes
/// read through the real file system).
pub fn load_material_shader(
    kind: MaterialShaderKind,
    name: &str,
    file: ShaderFile,
    sources: &mut SourceMap,
) -> Result<MaterialShader, Vec<Diagnostic>> {
    load_material_shader_with(kind, name, file, &RealFs, sources)
}

/// [`load_material_shader`] with includes read through `fs`.
pub fn load_material_shader_with(
    kind: MaterialShaderKind,
    name: &str,
    file: ShaderFile,
    fs: &dyn IncludeFs,
    sources: &mut SourceMap,
) -> Result<MaterialShader, Vec<Diagnostic>> {
    let root = sources.add(file.shown.clone(), file.text.clone());
    let origin = match (&file.path, file.shown.strip_prefix(BUILTIN_PREFIX)) {
        (Some(p), _) => IncludeOrigin::Disk(p.clone()),
        (None, Some(rel)) => IncludeOrigin::Builtin(rel.to_string()),
        (None, None) => IncludeOrigin::Memory,
    };
    let asm = assemble(root, &file.shown, &file.text, origin, fs, sources)?;
    let mut ck = Checker {
        kind,
        asm: &asm,
        root,
        sources,
        diags: Vec::new(),
    };
    let out = ck.check(name, &file.shown);
    match out {
        Some(mut m) if ck.diags.is_empty() => {
            m.text = asm.text.clone();
            m.assembly = asm;
            Ok(m)
        }
        _ => Err(ck.diags),
    }
}
