//! Which shadow-map layers a frame must render again (issue 26, point 3).
//!
//! A layer's depths depend on two things: the light's clip-from-world matrix
//! the layer was rendered with, and the casters inside that light volume. The
//! layer texture keeps its depths between frames, so a layer is rendered again
//! only when
//! - it was never rendered, or the texture was replaced (it grew);
//! - its matrix changed: the light moved or turned, a directional cascade moved
//!   to another square, or the casters' bounds changed (a directional light's
//!   depth range, and its squares over the whole scene);
//! - a caster changed inside its volume: an instance whose world transform
//!   differs from the one of the layer's last render, where the instance's box
//!   at either transform overlaps the layer's clip volume;
//! - a deformed (skinned or morphed) instance changed its pose: its vertices
//!   move within the instance, so every layer is rendered again (conservative:
//!   the pose does not bound the skinned vertices cheaply).
//!
//! Directional cascades under a moving camera (`cascades.rs` has the rule in
//! full): by default a cascade's square is taken from a world-fixed set, a
//! margin of 15 % larger than the slice of the view frustum it serves, its
//! centre on a grid of `floor(size × 0.15 / 1.15)` texels (267 of 2048) and its
//! half side on the ladder 2^(k/8), so the matrix changes only when the slice
//! crosses into another cell or onto another rung; a cascade at least as large
//! as the scene, or whose slice holds none of it, takes the scene's own square
//! and never moves. The choice depends on the frame alone, never on earlier
//! frames: a still equals the same frame of a sequence. The built-in room under
//! `fxrun`'s orbit renders 7 of its 40 layer-frames over 8 frames (33 with the
//! per-frame fit, `RendererOptions::stable_cascades` off).
//!
//! Everything is compared exactly (bit-equal matrices and poses): a cached
//! layer holds the same depths a fresh render would (tests/shadows.rs compares
//! the two frame by frame).

use super::upload::Geometry;
use crate::scene::{Aabb, InstancePose};
use glam::{Mat4, Vec4};

/// What changed among the shadow casters since the previous frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CasterChange {
    /// Nothing: every layer with an unchanged matrix is still valid.
    None,
    /// These world-space boxes (each moved instance at its old and its new
    /// transform) hold every change.
    Regions(Vec<Aabb>),
    /// A change without bounds (a new pose of a deformed instance).
    Everywhere,
}

/// The state the layers were rendered from.
#[derive(Debug, Default)]
pub(crate) struct ShadowCache {
    /// The matrix each layer's depths were rendered with (`None`: not valid).
    layers: Vec<Option<Mat4>>,
    /// Instance world transforms and deformed poses at the previous frame.
    transforms: Vec<Mat4>,
    poses: Vec<InstancePose>,
}

impl ShadowCache {
    /// Compares this frame's transforms and poses with the previous frame's,
    /// remembers them, and says what changed.
    pub fn casters_changed(
        &mut self,
        geometry: &Geometry,
        transforms: &[Mat4],
        poses: &[InstancePose],
    ) -> CasterChange {
        let change = if self.poses.as_slice() != poses || self.transforms.len() != transforms.len()
        {
            CasterChange::Everywhere
        } else {
            let regions: Vec<Aabb> = (0..transforms.len())
                .filter(|&i| self.transforms[i] != transforms[i])
                .flat_map(|i| {
                    [
                        geometry.instance_bounds(i, &self.transforms[i]),
                        geometry.instance_bounds(i, &transforms[i]),
                    ]
                })
                .filter(|b| !b.is_empty())
                .collect();
            if regions.is_empty() {
                CasterChange::None
            } else {
                CasterChange::Regions(regions)
            }
        };
        self.transforms.clear();
        self.transforms.extend_from_slice(transforms);
        self.poses.clear();
        self.poses.extend_from_slice(poses);
        change
    }

    /// Which of this frame's layers (`clip_from_world`, one per layer) must be
    /// rendered; records them as rendered. `fresh_texture`: the texture was
    /// replaced, nothing in it is valid.
    pub fn stale_layers(
        &mut self,
        clip_from_world: &[Mat4],
        change: &CasterChange,
        fresh_texture: bool,
    ) -> Vec<bool> {
        if fresh_texture {
            self.layers.clear();
        }
        self.layers
            .resize(clip_from_world.len().max(self.layers.len()), None);
        // layers this frame does not use are overwritten by nothing, but a light
        // may take them over later with another matrix: the matrix check covers it
        let stale: Vec<bool> = clip_from_world
            .iter()
            .zip(&self.layers)
            .map(|(m, cached)| *cached != Some(*m) || touches(m, change))
            .collect();
        for (slot, m) in self.layers.iter_mut().zip(clip_from_world) {
            *slot = Some(*m);
        }
        stale
    }
}

/// Whether `change` reaches into the clip volume of `clip_from_world`.
fn touches(clip_from_world: &Mat4, change: &CasterChange) -> bool {
    match change {
        CasterChange::None => false,
        CasterChange::Everywhere => true,
        CasterChange::Regions(boxes) => boxes.iter().any(|b| overlaps(clip_from_world, b)),
    }
}

/// Whether the world box `b` may overlap the clip volume (x, y in [-w, w], z in
/// [0, w]) of `m`: false only when all 8 corners lie outside one of its planes
/// (conservative: a box across a corner of the volume counts as inside).
pub(crate) fn overlaps(m: &Mat4, b: &Aabb) -> bool {
    // on the frame's path (every changed instance against every layer): no allocation
    let corners: [Vec4; 8] = std::array::from_fn(|i| {
        let p = glam::Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        *m * p.extend(1.0)
    });
    let planes: [fn(&Vec4) -> f32; 6] = [
        |c| c.w + c.x,
        |c| c.w - c.x,
        |c| c.w + c.y,
        |c| c.w - c.y,
        |c| c.z,
        |c| c.w - c.z,
    ];
    planes
        .iter()
        .all(|plane| corners.iter().any(|c| plane(c) >= 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::cascades::orthographic_rh;
    use crate::scene::perspective_rh;
    use glam::Vec3;

    fn cube(at: Vec3) -> Aabb {
        Aabb {
            min: at - Vec3::splat(0.5),
            max: at + Vec3::splat(0.5),
        }
    }

    #[test]
    fn boxes_inside_beside_and_behind_an_orthographic_volume() {
        // x, y in [-2, 2], depth 0 at z = -1 .. 1 at z = -9 (looking down -z)
        let m = orthographic_rh(-2.0, 2.0, -2.0, 2.0, 1.0, 9.0);
        assert!(overlaps(&m, &cube(Vec3::new(0.0, 0.0, -5.0))));
        assert!(
            overlaps(&m, &cube(Vec3::new(2.3, 0.0, -5.0))),
            "straddles x = 2"
        );
        assert!(!overlaps(&m, &cube(Vec3::new(3.0, 0.0, -5.0))));
        assert!(
            !overlaps(&m, &cube(Vec3::new(0.0, 0.0, 2.0))),
            "behind the near plane"
        );
        assert!(
            !overlaps(&m, &cube(Vec3::new(0.0, 0.0, -12.0))),
            "beyond the far plane"
        );
    }

    #[test]
    fn a_perspective_volume_excludes_what_is_behind_the_light() {
        let m = perspective_rh(1.0, 1.0, 0.1, 20.0);
        assert!(overlaps(&m, &cube(Vec3::new(0.0, 0.0, -5.0))));
        assert!(!overlaps(&m, &cube(Vec3::new(0.0, 0.0, 5.0))));
        assert!(
            !overlaps(&m, &cube(Vec3::new(8.0, 0.0, -3.0))),
            "outside the cone"
        );
    }

    #[test]
    fn layers_are_stale_until_rendered_and_when_their_matrix_or_casters_change() {
        let a = orthographic_rh(-2.0, 2.0, -2.0, 2.0, 1.0, 9.0);
        let b = Mat4::from_translation(Vec3::X) * a;
        let mut cache = ShadowCache::default();
        let none = CasterChange::None;
        assert_eq!(cache.stale_layers(&[a, b], &none, false), [true, true]);
        assert_eq!(cache.stale_layers(&[a, b], &none, false), [false, false]);
        assert_eq!(cache.stale_layers(&[b, b], &none, false), [true, false]);
        let inside_a = CasterChange::Regions(vec![cube(Vec3::new(0.0, 0.0, -5.0))]);
        let far_away = CasterChange::Regions(vec![cube(Vec3::new(50.0, 0.0, -5.0))]);
        assert_eq!(cache.stale_layers(&[a, b], &inside_a, false), [true, true]);
        assert_eq!(
            cache.stale_layers(&[a, b], &far_away, false),
            [false, false]
        );
        assert_eq!(
            cache.stale_layers(&[a, b], &CasterChange::Everywhere, false),
            [true, true]
        );
        assert_eq!(cache.stale_layers(&[a, b], &none, true), [true, true]);
    }
}
