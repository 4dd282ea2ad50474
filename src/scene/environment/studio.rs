//! `builtin:studio`: a procedural photo studio, for scenes that should look
//! "product-shot" lit with no file: a grey cyclorama (brighter towards the
//! horizon, a darker floor) and four rectangular soft boxes.
//!
//! | light | towards | size | radiance |
//! |---|---|---|---|
//! | key | (−1, 0.9, 1): front left, above | 0.5 × 0.4 (tangent units: ~53° × 44°) | 2.4 |
//! | fill | (1.2, 0.3, 0.8): front right, low | 0.6 × 0.45 | 0.6 |
//! | top | (0, 1, 0): overhead | 0.5 × 0.5 | 1.2 |
//! | rim | (0.2, 0.35, −1): behind | 0.12 × 0.6, a tall strip | 2 |
//!
//! Each box is a rectangle on the plane perpendicular to its direction, at
//! distance 1 (half-sizes above), its edges softened over 0.03. The walls are
//! 0.1 at the horizon falling to 0.048 at the zenith; the floor 0.032. A white
//! Lambertian surface facing up reflects radiance ≈ 0.8, facing +Z ≈ 0.55: the
//! level is chosen to sit beside a scene's own lights (fxrun lights every scene
//! with it by default; the default key light alone gives 1).

use super::Equirect;
use glam::Vec3;

/// A soft box: unit direction, half width and half height (tangent units),
/// radiance.
struct SoftBox {
    dir: Vec3,
    half: (f32, f32),
    radiance: f32,
}

fn boxes() -> [SoftBox; 4] {
    [
        SoftBox {
            dir: Vec3::new(-1.0, 0.9, 1.0).normalize(),
            half: (0.5, 0.4),
            radiance: 2.4,
        },
        SoftBox {
            dir: Vec3::new(1.2, 0.3, 0.8).normalize(),
            half: (0.6, 0.45),
            radiance: 0.6,
        },
        SoftBox {
            dir: Vec3::Y,
            half: (0.5, 0.5),
            radiance: 1.2,
        },
        SoftBox {
            dir: Vec3::new(0.2, 0.35, -1.0).normalize(),
            half: (0.12, 0.6),
            radiance: 2.0,
        },
    ]
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Radiance towards unit direction `d`.
pub fn studio_radiance(d: Vec3) -> Vec3 {
    let mut l = if d.y >= 0.0 { 0.25 - 0.13 * d.y } else { 0.08 };
    for b in boxes() {
        let c = d.dot(b.dir);
        if c <= 0.05 {
            continue;
        }
        // the box's plane basis: "up" towards +Y (or +Z for the top box)
        let helper = if b.dir.y.abs() > 0.9 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let right = helper.cross(b.dir).normalize();
        let up = b.dir.cross(right);
        let (x, y) = (d.dot(right) / c, d.dot(up) / c);
        let soft = 0.03;
        let inside = (1.0 - smoothstep(b.half.0 - soft, b.half.0 + soft, x.abs()))
            * (1.0 - smoothstep(b.half.1 - soft, b.half.1 + soft, y.abs()));
        l += b.radiance * inside;
    }
    Vec3::splat(l)
}

/// The studio as a `width` × `width / 2` map.
pub fn studio(width: u32) -> Equirect {
    Equirect::from_fn(width, studio_radiance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::environment::uv_to_direction;
    use std::f32::consts::PI;

    /// Irradiance / π on a surface of normal `n` (the radiance of a white
    /// Lambertian surface).
    fn lambert(m: &Equirect, n: Vec3) -> f32 {
        let mut e = 0.0;
        for y in 0..m.height {
            for x in 0..m.width {
                let d = uv_to_direction(
                    (x as f32 + 0.5) / m.width as f32,
                    (y as f32 + 0.5) / m.height as f32,
                );
                e += m.at(x, y).x * m.texel_solid_angle(y) * d.dot(n).max(0.0);
            }
        }
        e / PI
    }

    #[test]
    fn a_white_surface_is_about_white() {
        let m = studio(256);
        let up = lambert(&m, Vec3::Y);
        let front = lambert(&m, Vec3::Z);
        eprintln!("studio: white Lambert facing up {up:.3}, facing +Z {front:.3}");
        assert!((0.65..0.95).contains(&up) && (0.4..0.7).contains(&front));
    }
}
