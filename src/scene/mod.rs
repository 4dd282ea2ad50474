//! The scene model, without the GPU: what is drawn, not how.
//!
//! Meshes, instances, textures (decoded pixels), materials as data, lights and
//! cameras, and the loaders that build them (the built-in scenes, glTF 2.0, and
//! material files in the EFFECT language). Everything here is plain data tested on
//! the CPU like `script` and `graph`; the renderer (`crate::render`) consumes it.
//!
//! - [`model`]: [`Scene`], [`Mesh`], [`Instance`], [`TextureImage`], bounds;
//!   [`Scene::load`] (`load.rs`) picks the loader; [`error`]: [`SceneError`].
//! - [`camera`]: [`Camera`] and the `--camera` specs; [`light`]: [`Light`];
//!   [`material`]: [`Material`] (a surface + a lighting shader binding).
//! - [`environment`]: the light of the world around a scene ([`Environment`]: an
//!   equirectangular map from a file, the analytic sky, the studio), as data.
//! - [`builtin`]: the procedural scenes (`builtin:room`, `builtin:bench`, ...).
//! - [`gltf`]: validated glTF 2.0 loading (nodes, meshes, materials, lights,
//!   cameras).
//! - [`material_file`]: `MATERIAL.name = { ... }` files turned into [`Material`]s.
//! - [`node`]: the node hierarchy ([`Node`]) instances, lights and cameras hang on.
//! - [`animation`]: keyframe animation, skins and morph targets; [`Scene::pose`]
//!   poses the scene at a time ([`Pose`]), with a CPU reference of skinning.

pub mod animation;
pub mod builtin;
pub mod camera;
pub mod camera_path;
pub mod environment;
pub mod error;
pub mod gltf;
pub mod light;
mod load;
pub mod material;
pub mod material_file;
pub mod model;
pub mod node;

pub use animation::{
    Animation, Channel, ChannelPath, InstancePose, Interpolation, Playback, Pose, PosedMesh,
    Sampler, Selection, Skin, MAX_JOINTS, MAX_MORPH_TARGETS,
};
pub use camera::{look_to_rh, perspective_rh, Camera, NamedCamera};
pub use camera_path::{CameraPath, Orbit};
pub use environment::{
    Background, Environment, EnvironmentError, EnvironmentMap, EnvironmentSource,
};
pub use light::{Light, LightKind, ATTENUATION_THRESHOLD};
pub use material::{roughness_from_shininess, AlphaMode, Material, ShaderBinding};
pub use model::{
    Aabb, Instance, Mesh, MorphTarget, Rng, Scene, SceneError, TextureImage, MAX_MATERIALS,
};
pub use node::{Node, NodeTransform};
