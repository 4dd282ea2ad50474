//! Loading a scene: a built-in scene by name or a glTF file, given lights when it
//! has none and validated. Apart from the model (`model.rs`), which the loaders
//! build, so that the model imports no loader.

use super::error::SceneError;
use super::model::Scene;
use super::{builtin, gltf};

impl Scene {
    /// Loads `builtin:room`, `builtin:bench`, or a `.gltf` / `.glb` file.
    ///
    /// A scene without lights gets [`Scene::default_lights`].
    pub fn load(source: &str) -> Result<Scene, SceneError> {
        let mut scene = if let Some(name) = source.strip_prefix("builtin:") {
            builtin::builtin(name)?
        } else {
            gltf::load_gltf(std::path::Path::new(source))?
        };
        scene.ensure_lights();
        scene.validate()?;
        Ok(scene)
    }
}
