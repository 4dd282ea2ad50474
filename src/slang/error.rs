//! Why a slang preset cannot run: the file, the line where the GLSL compiler gives
//! one, and the failing semantic or feature by name.

use std::path::PathBuf;

/// A problem with a preset or one of its shaders.
#[derive(Debug, thiserror::Error)]
pub enum SlangError {
    /// The `.slangp` file itself (syntax, `#reference`, a missing file).
    #[error("{}: cannot parse the preset: {message}", path.display())]
    Preset { path: PathBuf, message: String },
    /// Reading or preprocessing a `.slang` file (`#include`, `#pragma`).
    #[error("{}: cannot preprocess the shader: {message}", path.display())]
    Preprocess { path: PathBuf, message: String },
    /// The GLSL compiler (glslang) rejected a shader: `path:line: message`.
    #[error("{}{}: GLSL error: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Glsl {
        path: PathBuf,
        line: Option<u32>,
        message: String,
    },
    /// The SPIR-V → WGSL translation (naga) failed, by failure class.
    #[error("{}: cannot translate to WGSL ({class}): {message}", path.display())]
    Translate {
        path: PathBuf,
        class: FailureClass,
        message: String,
    },
    /// A semantic (uniform or texture name) the preset's passes do not provide.
    #[error("{}: unknown semantic `{name}` (not a parameter, pass alias, LUT or standard semantic)", path.display())]
    Semantic { path: PathBuf, name: String },
    /// A preset feature fxgraph does not run.
    #[error("{}: {feature} is not supported: {why}", path.display())]
    Unsupported {
        path: PathBuf,
        feature: String,
        why: String,
    },
    /// Writing the lowered effect to the translation cache.
    #[error("{}: cannot write the lowered effect: {source}", path.display())]
    Cache {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The known classes of translation failure (docs/slang.md, "Coverage").
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FailureClass {
    /// A matrix passed between the vertex and fragment stages (WGSL forbids it).
    MatrixVarying,
    /// 16-bit floats (`float16_t`, FSR).
    Float16,
    /// naga: "special type is not registered".
    SpecialType,
    /// Anything else naga's SPIR-V front end or validator rejects.
    Other,
}

impl std::fmt::Display for FailureClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FailureClass::MatrixVarying => "matrix varying",
            FailureClass::Float16 => "float16",
            FailureClass::SpecialType => "special type not registered",
            FailureClass::Other => "naga",
        })
    }
}

impl FailureClass {
    /// The class of a naga error message.
    pub fn of(message: &str) -> FailureClass {
        let m = message.to_ascii_lowercase();
        if m.contains("special type") {
            FailureClass::SpecialType
        } else if m.contains("f16") || m.contains("float16") || m.contains("width: 2") {
            FailureClass::Float16
        } else if m.contains("user-defined entry point inputs or outputs")
            || (m.contains("mat") && (m.contains("location") || m.contains("varying")))
        {
            FailureClass::MatrixVarying
        } else {
            FailureClass::Other
        }
    }
}

impl SlangError {
    /// The file the error points at.
    pub fn path(&self) -> &std::path::Path {
        match self {
            SlangError::Preset { path, .. }
            | SlangError::Preprocess { path, .. }
            | SlangError::Glsl { path, .. }
            | SlangError::Translate { path, .. }
            | SlangError::Semantic { path, .. }
            | SlangError::Unsupported { path, .. }
            | SlangError::Cache { path, .. } => path,
        }
    }
}
