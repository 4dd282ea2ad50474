//! What a frame of a sequence adds to a still ([`FrameMotion`]: transforms now
//! and one frame earlier, the previous camera, the poses of deformed instances,
//! the sub-pixel jitter); the renderer applies it before drawing
//! (`renderer_pose.rs`).

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
    /// The camera cut between the previous frame and this one (a new shot,
    /// `CameraPath::cuts`): the motion vectors carry no camera motion (the
    /// previous camera is taken to be this frame's), only the objects' own.
    pub cut: bool,
    /// The poses of the deformed instances (skins, morph targets: those of
    /// `Scene::is_deformed`, in instance order), now and one frame earlier
    /// (`Pose::instances[i]`): only their joint matrices and morph weights are
    /// read, and the GPU deforms the vertices uploaded once
    /// (`crate::render::skinning`, the same result as
    /// [`crate::scene::Pose::deformed_mesh`]). Empty: the vertices at rest.
    pub deformed: Vec<crate::scene::InstancePose>,
    pub prev_deformed: Vec<crate::scene::InstancePose>,
}

impl FrameMotion {
    /// A frame of `scene` posed at `now`, one frame after `prev`: the instance
    /// transforms and the poses of the deformed instances at both (no previous
    /// camera, no jitter: set those fields after).
    pub fn posed(
        scene: &crate::scene::Scene,
        now: &crate::scene::Pose,
        prev: &crate::scene::Pose,
    ) -> FrameMotion {
        let transforms = |p: &crate::scene::Pose| p.instances.iter().map(|i| i.world).collect();
        let deformed = |p: &crate::scene::Pose| {
            (0..scene.instances.len())
                .filter(|&i| scene.is_deformed(i))
                .filter_map(|i| p.instances.get(i).cloned())
                .collect()
        };
        FrameMotion {
            transforms: transforms(now),
            prev_transforms: transforms(prev),
            deformed: deformed(now),
            prev_deformed: deformed(prev),
            ..Default::default()
        }
    }
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
