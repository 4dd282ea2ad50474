//! What a frame of a sequence adds to a still ([`FrameMotion`]: transforms now
//! and one frame earlier, the previous camera, deformed vertices, the sub-pixel
//! jitter) and how the renderer applies it before drawing ([`Renderer::pose`]).

use super::renderer::{RenderError, Renderer};
use crate::gpu::context::GpuContext;
use crate::scene::Camera;
use glam::{Mat4, Vec3};

/// What a frame of a sequence adds to a still: where everything was one frame
/// earlier (for the motion vectors, `AUX.motion`) and the sub-pixel jitter of the
/// frame's samples. The default is a still: the scene's own transforms, no
/// motion, no jitter.
#[derive(Debug, Clone, Default)]
pub struct FrameMotion {
    /// World transforms of the scene's instances (in `Scene::instances` order)
    /// at this frame; empty: the scene's (`Instance::transform`).
    pub transforms: Vec<Mat4>,
    /// The same one frame earlier (t − 1/fps); empty: as `transforms`.
    pub prev_transforms: Vec<Mat4>,
    /// The camera one frame earlier; `None`: this frame's camera.
    pub prev_camera: Option<Camera>,
    /// Offset of every pixel's sample from the pixel centre, in pixels (x right,
    /// y down): the projection is shifted so that pixel p shows what the
    /// unjittered camera shows at p + jitter. Motion vectors never contain it.
    pub jitter: [f32; 2],
    /// The vertices of the deformed instances (skins, morph targets: those of
    /// `Scene::is_deformed`, in instance order) in object space, now and one
    /// frame earlier ([`crate::scene::Pose::deformed_mesh`]); empty: at rest.
    pub deformed: Vec<crate::scene::PosedMesh>,
    pub prev_deformed: Vec<crate::scene::PosedMesh>,
}

/// `proj` shifted so that pixel p samples the unjittered image at p + `jitter`
/// (pixels, x right, y down) on a `width`×`height` target.
pub fn jittered(proj: Mat4, jitter: [f32; 2], width: u32, height: u32) -> Mat4 {
    if jitter == [0.0, 0.0] {
        return proj;
    }
    let t = Vec3::new(
        -2.0 * jitter[0] / width as f32,
        2.0 * jitter[1] / height as f32,
        0.0,
    );
    Mat4::from_translation(t) * proj
}

impl Renderer {
    /// Writes the instance transforms of `motion` (or the rest pose) and returns
    /// the world bounds and the draws of the instances that moved.
    pub(super) fn pose(
        &mut self,
        ctx: &GpuContext,
        motion: &FrameMotion,
    ) -> Result<(crate::scene::Aabb, Vec<super::upload::Batch>), RenderError> {
        let n = self.rest_transforms.len();
        for (what, t) in [
            ("transforms", &motion.transforms),
            ("previous transforms", &motion.prev_transforms),
        ] {
            if !t.is_empty() && t.len() != n {
                return Err(RenderError::Invalid(format!(
                    "{}: {} {what} for {n} instances",
                    self.name,
                    t.len()
                )));
            }
        }
        let now = if motion.transforms.is_empty() {
            &self.rest_transforms
        } else {
            &motion.transforms
        };
        let prev = if motion.prev_transforms.is_empty() {
            now
        } else {
            &motion.prev_transforms
        };
        if motion.transforms.is_empty() && motion.prev_transforms.is_empty() && !self.posed {
            return Ok((self.bounds, Vec::new()));
        }
        let d = self.geometry.deformed.len();
        if !motion.deformed.is_empty() {
            if motion.deformed.len() != d || motion.prev_deformed.len() != d {
                return Err(RenderError::Invalid(format!(
                    "{}: vertices for {} and {} deformed instances, the scene has {d}",
                    self.name,
                    motion.deformed.len(),
                    motion.prev_deformed.len()
                )));
            }
            self.geometry
                .write_deformed(ctx, &motion.deformed, &motion.prev_deformed);
        }
        let moving = self.geometry.moving(now, prev);
        let (now, prev) = (now.clone(), prev.clone());
        let bounds = self.geometry.write_transforms(ctx, &now, &prev);
        self.posed = !(motion.transforms.is_empty() && motion.prev_transforms.is_empty());
        self.motion.prepare(ctx, &moving)?;
        Ok((bounds, moving))
    }
}
