//! A scene camera as the effect runtime's standard camera values (`CAMERA.*` in
//! effect shaders): the scene layer knows no GPU types, so the conversion is here.

use crate::gpu::executor::CameraStd;
use crate::scene::Camera;

/// The camera's projection for `aspect` (width / height) as [`CameraStd`].
pub fn camera_std(camera: &Camera, aspect: f32) -> CameraStd {
    let proj = camera.proj(aspect);
    CameraStd {
        near: camera.near,
        far: camera.far,
        proj: proj.to_cols_array(),
        inv_proj: proj.inverse().to_cols_array(),
    }
}
