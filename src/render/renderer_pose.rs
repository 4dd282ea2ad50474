//! How the renderer applies a [`FrameMotion`] before drawing: the instance
//! transforms now and one frame earlier, and the poses of the deformed
//! instances for the skinning pass. (Methods of [`Renderer`]; the renderer
//! itself does not import this file.)

use super::error::RenderError;
use super::frame_motion::FrameMotion;
use super::renderer::Renderer;
use super::shadow_cache::CasterChange;
use crate::gpu::context::GpuContext;

impl Renderer {
    /// Writes the instance transforms of `motion` (or the rest pose) and returns
    /// the world bounds and the draws of the instances that moved.
    pub(super) fn pose(
        &mut self,
        ctx: &GpuContext,
        motion: &FrameMotion,
    ) -> Result<(crate::scene::Aabb, Vec<super::upload::Batch>), RenderError> {
        self.deform(ctx, motion)?;
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
        let moving = self.geometry.moving(now, prev);
        let (now, prev) = (now.clone(), prev.clone());
        let bounds = self.geometry.write_transforms(ctx, &now, &prev);
        self.posed = !(motion.transforms.is_empty() && motion.prev_transforms.is_empty());
        self.motion.prepare(ctx, &moving)?;
        Ok((bounds, moving))
    }

    /// What changed among the shadow casters since the previous frame
    /// (`shadow_cache.rs`).
    pub(super) fn caster_change(&mut self, motion: &FrameMotion) -> CasterChange {
        let now = if motion.transforms.is_empty() {
            &self.rest_transforms
        } else {
            &motion.transforms
        };
        self.shadow_maps
            .casters_changed(&self.geometry, now, &motion.deformed)
    }

    /// Writes the poses of the deformed instances for the skinning pass (or
    /// their rest pose when `motion` has none).
    fn deform(&mut self, ctx: &GpuContext, motion: &FrameMotion) -> Result<(), RenderError> {
        let d = self.geometry.deformed.len();
        let Some(skinning) = self.geometry.skinning.as_mut() else {
            return Ok(());
        };
        if motion.deformed.is_empty() && motion.prev_deformed.is_empty() {
            skinning.rest(ctx);
            return Ok(());
        }
        if motion.deformed.len() != d || motion.prev_deformed.len() != d {
            return Err(RenderError::Invalid(format!(
                "{}: poses for {} and {} deformed instances, the scene has {d}",
                self.name,
                motion.deformed.len(),
                motion.prev_deformed.len()
            )));
        }
        skinning
            .write_pose(ctx, &motion.deformed, &motion.prev_deformed)
            .map_err(|e| RenderError::Invalid(format!("{}: {e}", self.name)))
    }
}
