//! The scene's and the renderer's errors as run errors: a scene, material or
//! environment problem is an input error naming the file.

use super::error::RunError;
use crate::io::IoError;
use crate::render::RenderError;
use crate::scene::SceneError;
use std::path::PathBuf;

/// A scene error as an input error naming the file (the glTF file, or the `--scene`
/// argument where there is none).
pub(super) fn scene_error(scene: &str, e: SceneError) -> RunError {
    let (path, message) = match e {
        SceneError::Gltf { path, message } => (path, message),
        SceneError::Empty(name) => (name, "the scene has no triangles to draw".to_string()),
        SceneError::TooManyMaterials { name, count } => (
            name,
            format!(
                "{count} materials, at most {} are supported (8-bit material id)",
                crate::scene::MAX_MATERIALS
            ),
        ),
        other => (scene.to_string(), other.to_string()),
    };
    RunError::BadInput(IoError::Decode {
        path: PathBuf::from(path),
        message,
    })
}

/// A renderer error as a run error (a scene or material problem is an input error).
pub fn render_error(scene: &str, e: RenderError) -> RunError {
    match e {
        RenderError::Gpu(g) => RunError::Gpu(g),
        RenderError::Scene(s) => scene_error(scene, s),
        RenderError::Invalid(m) => RunError::BadInput(IoError::Unsupported {
            path: PathBuf::from(scene),
            message: m,
        }),
        RenderError::Material(rendered) => RunError::Rejected { rendered },
        RenderError::Environment(e) => environment_error(e),
    }
}

pub(super) fn environment_error(e: crate::scene::EnvironmentError) -> RunError {
    use crate::scene::EnvironmentError as E;
    match e {
        E::Io(io) => RunError::from(io),
        E::Invalid { path, message } => RunError::BadInput(IoError::Decode {
            path: PathBuf::from(path),
            message,
        }),
        E::Spec(message) => RunError::Rejected { rendered: message },
    }
}
