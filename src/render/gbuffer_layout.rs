//! [`GbufferLayout`]: how deferred shading's geometry stage fills the
//! G-buffer (`fxrun --gbuffer-layout fat|visibility`).

use super::cli_names::cli_names;
use std::str::FromStr;

/// How the deferred geometry stage fills the G-buffer (the targets the light
/// pass, the AUX resolve and the effects read are the same either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum GbufferLayout {
    /// One raster pass runs every surface shader and writes the G-buffer
    /// targets (the default).
    #[default]
    Fat,
    /// A raster pass writes depth and a triangle id per pixel; compute
    /// dispatches resolve the materials into the same targets
    /// (`super::visibility`). Draws that cannot be resolved in compute (alpha
    /// test, layered surfaces, derivatives of their own) are still drawn into
    /// the G-buffer; on an adapter without `@builtin(primitive_index)` or a
    /// storable `Rgb10a2Unorm`, every draw is.
    Visibility,
}

cli_names!(GbufferLayout {
    Fat => "fat",
    Visibility => "visibility",
});

impl FromStr for GbufferLayout {
    type Err = String;

    /// `fat` (or `gbuffer`), `visibility` (or `visbuf`, `vis`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "fat" | "gbuffer" | "g-buffer" => Ok(GbufferLayout::Fat),
            "visibility" | "visbuf" | "vis" | "visibility-buffer" => Ok(GbufferLayout::Visibility),
            other => Err(format!(
                "unknown G-buffer layout `{other}` (use fat or visibility)"
            )),
        }
    }
}
