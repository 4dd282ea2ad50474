//! The map as a small cube map on the CPU: the source of the exact
//! convolutions of prefilter.wgsl's `fs_convolve` (the wide GGX lobes and the
//! irradiance).

use crate::scene::environment::{direction_to_uv, uv_to_direction, Equirect};
use glam::Vec3;

/// The cube face (+X, −X, +Y, −Y, +Z, −Z) and texel of unit direction `d` on a
/// cube of side `side` (the Vulkan / WebGPU face selection table, as
/// prefilter.wgsl's `face_direction` inverted).
fn cube_texel_of(d: Vec3, side: u32) -> (usize, u32, u32) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    let to = |s: f32| (((s / ma + 1.0) * 0.5 * side as f32) as u32).min(side - 1);
    (face, to(sc), to(tc))
}

/// The map as a small cube of side `side`, every texel (direction xyz, solid
/// angle, radiance rgb, 0): the solid-angle-weighted mean of the map's texels
/// whose centres fall in it (the map's own value at its centre when none does:
/// a map smaller than the cube).
pub(crate) fn cube_texels(map: &Equirect, side: u32) -> Vec<[f32; 8]> {
    let mut acc = vec![(Vec3::ZERO, 0.0f32); (6 * side * side) as usize];
    for y in 0..map.height {
        let omega = map.texel_solid_angle(y);
        for x in 0..map.width {
            let d = uv_to_direction(
                (x as f32 + 0.5) / map.width as f32,
                (y as f32 + 0.5) / map.height as f32,
            );
            let (f, cx, cy) = cube_texel_of(d, side);
            let i = (f as u32 * side * side + cy * side + cx) as usize;
            acc[i].0 += map.at(x, y) * omega;
            acc[i].1 += omega;
        }
    }
    let mut out = Vec::with_capacity(acc.len());
    for face in 0..6u32 {
        for y in 0..side {
            for x in 0..side {
                let s = 2.0 * (x as f32 + 0.5) / side as f32 - 1.0;
                let t = 2.0 * (y as f32 + 0.5) / side as f32 - 1.0;
                let d = match face {
                    0 => Vec3::new(1.0, -t, -s),
                    1 => Vec3::new(-1.0, -t, s),
                    2 => Vec3::new(s, 1.0, t),
                    3 => Vec3::new(s, -1.0, -t),
                    4 => Vec3::new(s, -t, 1.0),
                    _ => Vec3::new(-s, -t, -1.0),
                };
                let q = 1.0 + s * s + t * t;
                let omega = 4.0 / (side * side) as f32 / (q * q.sqrt());
                let d = d.normalize();
                let (sum, w) = acc[(face * side * side + y * side + x) as usize];
                let l = if w > 0.0 {
                    sum / w
                } else {
                    let (u, v) = direction_to_uv(d);
                    map.at(
                        ((u * map.width as f32) as u32).min(map.width - 1),
                        ((v * map.height as f32) as u32).min(map.height - 1),
                    )
                };
                out.push([d.x, d.y, d.z, omega, l.x, l.y, l.z, 0.0]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_small_cube_keeps_the_map_and_covers_the_sphere() {
        let map = Equirect::from_fn(256, |d| Vec3::new(1.0 + d.x, 2.0, 0.5));
        let t = cube_texels(&map, 16);
        let omega: f32 = t.iter().map(|e| e[3]).sum();
        assert!((omega - 4.0 * std::f32::consts::PI).abs() < 0.02, "{omega}");
        for e in &t {
            // each texel's radiance is its direction's (within the texel's spread)
            assert!((e[4] - (1.0 + e[0])).abs() < 0.1 && (e[5] - 2.0).abs() < 1e-4);
            let (f, x, y) = cube_texel_of(Vec3::new(e[0], e[1], e[2]), 16);
            let i = t.iter().position(|q| q == e).unwrap();
            assert_eq!(i, (f as u32 * 256 + y * 16 + x) as usize);
        }
    }
}
