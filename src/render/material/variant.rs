//! How material features select shader code (the materials-and-effects paper: "conditional compilation"),
//! and the keys under which compiled variants are cached.
//!
//! Three modes, selected with `fxrun --variants MODE`, so the paper's claim (1.5–2×
//! faster than run-time branches) can be measured:
//! - [`VariantMode::Preprocess`]: `#ifdef FLAG` blocks are kept or dropped by the
//!   preprocessor and the forward light count is a `const`: one shader module per
//!   feature set (the paper's uber-shader).
//! - [`VariantMode::Override`]: one module per surface/lighting pair; features are
//!   WGSL `override` booleans and the light count an `override` integer, set as
//!   pipeline constants (the driver specialises each pipeline).
//! - [`VariantMode::Branch`]: one module and one pipeline per surface/lighting
//!   pair; features are bits of a per-material uniform tested at run time and the
//!   light count is read from the frame uniform.

use crate::render::cli_names::cli_names;
use std::str::FromStr;

pub use crate::shader::features::{texture_flag, ENGINE_FLAGS};

/// Bit of [`ENGINE_FLAGS`] entry `name`.
pub fn engine_bit(name: &str) -> u64 {
    1 << ENGINE_FLAGS
        .iter()
        .position(|f| *f == name)
        .expect("an engine flag")
}

/// How features become code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum VariantMode {
    /// `#ifdef` preprocessing: one module per feature set.
    #[default]
    Preprocess,
    /// WGSL `override` constants set per pipeline.
    Override,
    /// Run-time branches on uniform flag bits.
    Branch,
}

cli_names!(VariantMode {
    Preprocess => "preprocess",
    Override => "override",
    Branch => "branch",
});

impl FromStr for VariantMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "preprocess" | "ifdef" | "preprocessor" => Ok(VariantMode::Preprocess),
            "override" | "constants" | "overrides" => Ok(VariantMode::Override),
            "branch" | "uniform" | "runtime" => Ok(VariantMode::Branch),
            other => Err(format!(
                "unknown variant mode `{other}` (use preprocess, override or branch)"
            )),
        }
    }
}

/// A compiled material variant: which shaders, and which features are on (bits
/// over [`ENGINE_FLAGS`] followed by the surface's texture flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VariantKey {
    /// Index into the scene's distinct surface shaders.
    pub surface: usize,
    /// Lighting model id: index into the scene's distinct lighting shaders.
    pub lighting: usize,
    pub features: u64,
}

impl VariantKey {
    /// The names of the features that are on, for a surface with `flags`.
    pub fn feature_names<'a>(&self, flags: &'a [String]) -> Vec<&'a str> {
        flags
            .iter()
            .enumerate()
            .filter(|(i, _)| self.features & (1 << i) != 0)
            .map(|(_, f)| f.as_str())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_flags_follow_the_paper() {
        assert_eq!(texture_flag("diffuse_map"), "HAS_DIFFUSE_MAP");
        assert_eq!(engine_bit("ALPHA_MASK"), 1);
        assert_eq!(engine_bit("HAS_TANGENTS"), 32);
    }
}
