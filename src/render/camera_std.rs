//! A scene camera as the effect runtime's standard camera values (`CAMERA.*` in
//! effect shaders): the scene layer knows no GPU types, so the conversion is here.

use crate::gpu::executor::CameraStd;
use crate::scene::Camera;
use glam::Mat4;

/// The camera with projection `proj` (the frame's: jittered when the frame is)
/// as [`CameraStd`], so that effects reconstruct positions from the AUX images
/// with the projection they were rendered with.
pub fn camera_std(camera: &Camera, proj: &Mat4) -> CameraStd {
    CameraStd {
        near: camera.near,
        far: camera.far,
        proj: proj.to_cols_array(),
        inv_proj: proj.inverse().to_cols_array(),
    }
}
