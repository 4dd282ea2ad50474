//! Where a directional light's cascade maps sit: the light-space square each
//! cascade is rendered over, and its depth range (issue 26, point 3).
//!
//! Two fits, both a function of the frame alone (no history: a frame of a
//! sequence equals the same frame rendered as a still):
//! - [`refit`], the per-frame fit (`RendererOptions::stable_cascades` off, the
//!   reference): the square round the bounding sphere of the cascade's slice of
//!   the view frustum, its centre snapped to whole texels, its depth range the
//!   scene's stretched over the sphere. The centre slides with the camera, so a
//!   moving camera renders the cascade again nearly every frame.
//! - [`stable`], the default: the square is chosen from a coarse, world-fixed
//!   set, so it stays put while the camera moves inside a cell:
//!   1. a slice whose sphere misses the scene's bounds has no receivers, and a cascade whose square would be at least as large as
//!      the scene's light-space square needs no other: both take the scene's
//!      square (centred on the scene's bounds: it never moves);
//!   2. otherwise the half side is the sphere's radius plus a margin of
//!      [`MARGIN`], rounded up to the ladder 2^(k / [`LADDER_STEPS`]) (so
//!      the slow growth and shrinking of a slice keeps its radius), and the centre
//!      is the sphere's centre rounded to a world-fixed grid of
//!      `floor(size × MARGIN / (1 + MARGIN))` texels: the rounding moves it by
//!      at most half a cell, which the margin holds, so the slice stays inside
//!      the square;
//!   3. the depth range is the scene's (every receiver lies in the scene's
//!      bounds), not stretched over the sphere, so it does not move either.
//!
//! `shadow_cache.rs` renders a layer again only when its matrix changes: with
//! the stable fit, when the slice crosses into another cell or onto another
//! rung of the ladder, or the scene's bounds change.

use crate::scene::Aabb;
use glam::{Mat4, Vec2, Vec3, Vec4};

/// Extra half side of a stable cascade, as a fraction of the slice's radius
/// (chosen by measurement: docs/renderer.md, "Caching").
pub(crate) const MARGIN: f32 = 0.15;
/// Rungs of the radius ladder per doubling.
pub(crate) const LADDER_STEPS: f32 = 8.0;

/// A cascade's map in light space: x, y in `center ± half`, light-space z
/// (looking down -z) in `z.0 .. z.1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CascadeSquare {
    pub center: Vec2,
    pub half: f32,
    pub z: (f32, f32),
}

impl CascadeSquare {
    /// World → light clip (depth 0..1), with a little depth margin.
    pub fn clip_from_light(&self) -> Mat4 {
        let (lo, hi) = self.z;
        let margin = (hi - lo) * 0.01 + 1e-4;
        let (c, h) = (self.center, self.half);
        orthographic_rh(
            c.x - h,
            c.x + h,
            c.y - h,
            c.y + h,
            -hi - margin,
            -lo + margin,
        )
    }

    /// World size of one of the `size` texels across.
    pub fn texel(&self, size: f32) -> f32 {
        2.0 * self.half / size
    }
}

/// Right-handed orthographic projection to depth 0 (`-near`) .. 1 (`-far`).
pub(crate) fn orthographic_rh(
    left: f32,
    right: f32,
    bottom: f32,
    top: f32,
    near: f32,
    far: f32,
) -> Mat4 {
    let (w, h, d) = (right - left, top - bottom, near - far);
    Mat4::from_cols(
        Vec4::new(2.0 / w, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 / h, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 1.0 / d, 0.0),
        Vec4::new(-(right + left) / w, -(top + bottom) / h, near / d, 1.0),
    )
}

/// The per-frame fit of the sphere (`c`, `r`) in light space (`r` with its
/// border texels), over the scene's light-space box `scene`.
pub(crate) fn refit(c: Vec3, r: f32, scene: &Aabb, size: f32) -> CascadeSquare {
    // snapped to whole texels: a moving camera slides the map by whole texels,
    // so the rasterised shadow edges stay put
    let texel = 2.0 * r / size;
    CascadeSquare {
        center: Vec2::new((c.x / texel).floor(), (c.y / texel).floor()) * texel,
        half: r,
        z: (scene.min.z.min(c.z - r), scene.max.z.max(c.z + r)),
    }
}

/// The stable fit (the module's rule) of the sphere (`c`, `r`) in light space
/// (`r` with its border texels), over the scene's light-space box `scene`;
/// `border` is the factor the border texels add to a radius; `empty`: the
/// sphere holds none of the scene ([`misses`] in world space).
pub(crate) fn stable(
    c: Vec3,
    r: f32,
    scene: &Aabb,
    (size, border): (f32, f32),
    empty: bool,
) -> CascadeSquare {
    let z = (scene.min.z, scene.max.z);
    let whole = CascadeSquare {
        center: scene.center().truncate(),
        half: (scene.max - scene.min).truncate().max_element() * 0.5 * border,
        z,
    };
    let half = ladder_up(r * (1.0 + MARGIN));
    if empty || whole.half <= half {
        return whole;
    }
    let cell = cell_texels(size) * 2.0 * half / size;
    CascadeSquare {
        center: (c.truncate() / cell).round() * cell,
        half,
        z,
    }
}

/// The grid a stable cascade's centre is rounded to, in texels: rounding moves
/// the centre by at most half a cell, `half × MARGIN / (1 + MARGIN)`, what the
/// margin adds (`half` is at least `r × (1 + MARGIN)`).
fn cell_texels(size: f32) -> f32 {
    (size * MARGIN / (1.0 + MARGIN)).floor().max(1.0)
}

/// The smallest rung of the ladder 2^(k / LADDER_STEPS) not below `x`.
fn ladder_up(x: f32) -> f32 {
    let k = (x.log2() * LADDER_STEPS).ceil();
    let rung = (k / LADDER_STEPS).exp2();
    // exp2 may land a hair below x when x is on a rung
    if rung < x {
        ((k + 1.0) / LADDER_STEPS).exp2()
    } else {
        rung
    }
}

/// Whether the sphere (`c`, `r`) misses the box `b` (both in world space: the
/// scene's light-space box is larger than the scene).
pub(crate) fn misses(c: Vec3, r: f32, b: &Aabb) -> bool {
    let nearest = c.clamp(b.min, b.max);
    (nearest - c).length_squared() > r * r
}

/// The far end of the cascades for the stable fit: the far side of the
/// scene's bounding sphere seen from the eye. It depends on the eye's position
/// alone (an orbit or a turning camera keeps it, so the split depths and the
/// cascades' radii stay) and is never nearer than the scene's farthest corner.
pub(crate) fn stable_far(eye: Vec3, bounds: &Aabb) -> f32 {
    (eye - bounds.center()).length() + bounds.diagonal() * 0.5
}

#[cfg(test)]
#[path = "cascades_tests.rs"]
mod tests;
