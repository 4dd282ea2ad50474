//! [`SceneError`]: what building, loading or querying a scene can fail with. Its
//! own home, so the scene's parts (cameras, animation, loaders) return it without
//! importing the model.

/// Most materials a scene may have: the material id is stored in 8 bits.
pub const MAX_MATERIALS: usize = 256;

/// Errors of building, loading or querying a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A glTF file could not be loaded; the message says why.
    #[error("{path}: {message}")]
    Gltf { path: String, message: String },
    /// `builtin:NAME` with an unknown NAME.
    #[error("unknown built-in scene `{0}` (available: builtin:room, builtin:bench)")]
    UnknownBuiltin(String),
    /// A `--camera` spec that does not parse or names no camera.
    #[error("camera `{spec}`: {message}")]
    Camera { spec: String, message: String },
    /// The scene has nothing to draw.
    #[error("{0}: the scene has no triangles to draw")]
    Empty(String),
    /// More than [`MAX_MATERIALS`] materials.
    #[error(
        "{name}: {count} materials, at most {MAX_MATERIALS} are supported (8-bit material id)"
    )]
    TooManyMaterials { name: String, count: usize },
    /// An `--animation` choice that names no animation of the scene.
    #[error("animation `{spec}`: {message}")]
    Playback { spec: String, message: String },
    /// Nodes, skins, morph targets or animations that do not fit together.
    #[error("{name}: {message}")]
    Animation { name: String, message: String },
}
