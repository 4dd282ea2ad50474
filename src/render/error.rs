//! [`RenderError`]: what rendering can fail with. Its own home, so the
//! renderer's parts return it without importing the renderer.

use crate::gpu::context::GpuError;
use crate::scene::SceneError;

/// Errors of rendering.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Something about the request itself (size, texture too large, ...).
    #[error("{0}")]
    Invalid(String),
    /// A material that cannot be used (unknown shader, bad parameter, ...).
    #[error("{0}")]
    Material(String),
    /// The environment map could not be used (missing, not equirectangular, ...).
    #[error(transparent)]
    Environment(#[from] crate::scene::EnvironmentError),
}
