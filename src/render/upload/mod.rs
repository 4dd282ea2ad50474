//! Uploading a scene, once, when the renderer is made:
//! - `geometry`: one vertex and one index buffer for every mesh, instances sorted
//!   into batches, the private vertex ranges of deformed (skinned, morphed)
//!   instances; per frame only the instance transforms are written, and the
//!   joints and morph weights of the deformed ones (`skinning`: deformed on the GPU per frame);
//! - `textures`: the scene's images, mipmapped, sRGB or linear as the surface
//!   shader declares;
//! - `materials`: the per-material bind groups (group 2) and lighting parameter
//!   arrays (group 3).

mod geometry;
mod materials;
pub(crate) mod skinning;
mod textures;

pub(crate) use geometry::{Batch, Cull, Deformed, Geometry};
pub(crate) use materials::MaterialResources;
