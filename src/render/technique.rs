//! The shading techniques a [`super::Renderer`] draws a frame with.

use super::cli_names::cli_names;
use std::str::FromStr;

/// How a frame is shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Technique {
    /// Deferred shading with the compressed G-buffer and light volumes (Tang et al.).
    #[default]
    Deferred,
    /// Light pre-pass (the deferred-rendering survey): depth + normals, light buffer, final geometry pass.
    LightPrepass,
    /// Forward shading: every visible light per fragment.
    Forward,
}

cli_names!(Technique {
    Deferred => "deferred",
    LightPrepass => "light-prepass",
    Forward => "forward",
});

impl FromStr for Technique {
    type Err = String;

    /// `deferred`, `light-prepass` (or `lpp`, `prepass`), `forward`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "deferred" => Ok(Technique::Deferred),
            "light-prepass" | "lightprepass" | "lpp" | "prepass" | "light-pre-pass" => {
                Ok(Technique::LightPrepass)
            }
            "forward" => Ok(Technique::Forward),
            other => Err(format!(
                "unknown renderer `{other}` (use deferred, light-prepass or forward)"
            )),
        }
    }
}
