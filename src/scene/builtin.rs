//! Built-in procedural scenes (`builtin:room`, `builtin:bench`) and the mesh
//! generators they and the light volumes use.

use super::model::{Camera, Instance, Light, Material, Mesh, NamedCamera, Scene, SceneError};
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::f32::consts::PI;

/// The built-in scene `name` (`room` or `bench`).
pub fn builtin(name: &str) -> Result<Scene, SceneError> {
    match name {
        "room" => Ok(room()),
        "bench" => Ok(bench()),
        other => Err(SceneError::UnknownBuiltin(other.to_string())),
    }
}

/// An axis-aligned box centred at the origin with the given full size; 24
/// vertices (flat normals), 12 triangles, CCW outside.
pub fn box_mesh(size: Vec3) -> Mesh {
    let h = size * 0.5;
    let mut m = Mesh {
        name: "box".into(),
        ..Default::default()
    };
    // (normal, tangent u axis, bitangent v axis)
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (n, u, v) in faces {
        let base = m.positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let p = (n + u * su + v * sv) * h;
            m.positions.push(p);
            m.normals.push(n);
            m.uvs
                .push(Vec2::new((su + 1.0) * 0.5, 1.0 - (sv + 1.0) * 0.5));
        }
        m.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m.compute_tangents();
    m
}

/// A UV sphere of radius 1 with `segments` around and `rings` from pole to pole.
pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
    let mut m = Mesh {
        name: "sphere".into(),
        ..Default::default()
    };
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            m.positions.push(n);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            if r != 0 {
                m.indices.extend_from_slice(&[a, b, a + 1]);
            }
            if r != rings - 1 {
                m.indices.extend_from_slice(&[a + 1, b, b + 1]);
            }
        }
    }
    m.compute_tangents();
    m
}

/// A flat square in the XZ plane (normal +Y), side 1, split into `n`×`n` cells.
pub fn grid_plane(n: u32) -> Mesh {
    let mut m = Mesh {
        name: "plane".into(),
        ..Default::default()
    };
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            m.positions.push(Vec3::new(u - 0.5, 0.0, v - 0.5));
            m.normals.push(Vec3::Y);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = n + 1;
    for j in 0..n {
        for i in 0..n {
            let a = j * row + i;
            m.indices
                .extend_from_slice(&[a, a + row, a + 1, a + 1, a + row, a + row + 1]);
        }
    }
    m.tangents = Some(vec![Vec4::new(1.0, 0.0, 0.0, 1.0); m.positions.len()]);
    m
}

/// An icosphere with unit-length vertices, subdivided `subdivisions` times, CCW
/// outside (a light volume proxy; only positions are meaningful).
pub fn icosphere(subdivisions: u32) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut pos: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, pos: &mut Vec<Vec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *cache.entry(key).or_insert_with(|| {
                pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalize());
                pos.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = mid(a, b, &mut pos);
            let bc = mid(b, c, &mut pos);
            let ca = mid(c, a, &mut pos);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    let mut m = Mesh {
        name: "icosphere".into(),
        normals: pos.clone(),
        uvs: vec![Vec2::ZERO; pos.len()],
        positions: pos,
        indices: tris.into_iter().flatten().collect(),
        tangents: None,
        ..Default::default()
    };
    m.name = format!("icosphere{subdivisions}");
    m
}

/// A closed cone with its apex at the origin, axis +Z, base circle of radius 1 at
/// z = 1, `segments` sides, CCW outside (a spot light volume proxy).
pub fn cone(segments: u32) -> Mesh {
    let mut m = Mesh {
        name: "cone".into(),
        ..Default::default()
    };
    m.positions.push(Vec3::ZERO);
    m.positions.push(Vec3::Z);
    for s in 0..segments {
        let a = s as f32 / segments as f32 * std::f32::consts::TAU;
        m.positions.push(Vec3::new(a.cos(), a.sin(), 1.0));
    }
    for s in 0..segments {
        let i = 2 + s;
        let j = 2 + (s + 1) % segments;
        // side: apex, next, current is CCW seen from outside
        m.indices.extend_from_slice(&[0, j, i]);
        // base cap faces +Z
        m.indices.extend_from_slice(&[1, i, j]);
    }
    m.normals = vec![Vec3::Z; m.positions.len()];
    m.uvs = vec![Vec2::ZERO; m.positions.len()];
    m
}

/// Smallest distance from the origin to the plane of any triangle of `m` (the
/// radius of the largest origin-centred sphere inside a convex mesh).
pub fn inradius(m: &Mesh) -> f32 {
    m.indices
        .chunks_exact(3)
        .map(|t| {
            let (a, b, c) = (
                m.positions[t[0] as usize],
                m.positions[t[1] as usize],
                m.positions[t[2] as usize],
            );
            let n = (b - a).cross(c - a).normalize_or_zero();
            n.dot(a).abs()
        })
        .fold(f32::INFINITY, f32::min)
}

struct Builder {
    scene: Scene,
}

impl Builder {
    fn new(name: &str) -> Self {
        Builder {
            scene: Scene {
                name: format!("builtin:{name}"),
                ..Default::default()
            },
        }
    }

    fn mesh(&mut self, m: Mesh) -> usize {
        self.scene.meshes.push(m);
        self.scene.meshes.len() - 1
    }

    /// Adds every material of an embedded material file (and its textures); the
    /// built-in files are tested to load, so a failure here is a bug.
    fn materials_from(&mut self, text: &str, shown: &str) -> HashMap<String, usize> {
        let file =
            super::material_file::load_materials(shown, text, None, self.scene.textures.len())
                .unwrap_or_else(|report| panic!("built-in materials do not load:\n{report}"));
        self.scene.textures.extend(file.textures);
        file.materials
            .into_iter()
            .map(|m| {
                let name = m.name.clone();
                (name, self.material(m))
            })
            .collect()
    }

    fn material(&mut self, m: Material) -> usize {
        self.scene.materials.push(m);
        self.scene.materials.len() - 1
    }

    /// Adds `light` under the name `name`.
    fn light(&mut self, name: &str, light: Light) {
        self.scene.lights.push(Light {
            name: name.to_string(),
            ..light
        });
    }

    /// Adds the camera `name` at `eye` looking at `target` (up +Y), with a
    /// vertical field of view of `fov_y_degrees`.
    fn camera(
        &mut self,
        name: &str,
        eye: Vec3,
        target: Vec3,
        fov_y_degrees: f32,
        near: f32,
        far: f32,
    ) {
        self.scene.cameras.push(NamedCamera {
            name: name.to_string(),
            node: None,
            camera: Camera {
                eye,
                target,
                up: Vec3::Y,
                fov_y: fov_y_degrees.to_radians(),
                near,
                far,
            },
        });
    }

    fn place(&mut self, name: &str, mesh: usize, material: usize, transform: Mat4) {
        self.scene.instances.push(Instance {
            name: name.to_string(),
            mesh,
            material,
            transform,
            ..Default::default()
        });
    }
}

/// The material definitions of the built-in scenes.
pub const ROOM_MATERIALS: &str = include_str!("../../materials/room.fx");
pub const BENCH_MATERIALS: &str = include_str!("../../materials/bench.fx");

/// `builtin:room`: a floor and three walls, boxes and spheres of assorted
/// materials (one emissive, one transparent), 24 coloured point lights (intensity
/// 4, radius 6..9), a spot
/// light, a dim directional light and ambient light. One camera, "room".
pub fn room() -> Scene {
    let mut b = Builder::new("room");
    let cube = b.mesh(box_mesh(Vec3::ONE));
    let sphere = b.mesh(uv_sphere(48, 24));
    let mats = b.materials_from(ROOM_MATERIALS, "<builtin>/materials/room.fx");
    place_room_shell(&mut b, cube, |name| mats[name]);
    place_room_props(&mut b, (cube, sphere), |name| mats[name]);
    add_room_lights(&mut b);
    b.camera(
        "room",
        Vec3::new(0.0, 4.0, 11.0),
        Vec3::new(0.0, 1.2, -1.0),
        50.0,
        0.1,
        40.0,
    );
    b.scene.background = Vec3::new(0.02, 0.02, 0.03);
    b.scene
}

/// The room's floor and three walls (`material` names a material of
/// `materials/room.fx`).
fn place_room_shell(b: &mut Builder, cube: usize, material: impl Fn(&str) -> usize) {
    let s = |x: f32, y: f32, z: f32| Mat4::from_scale(Vec3::new(x, y, z));
    let t = |x: f32, y: f32, z: f32| Mat4::from_translation(Vec3::new(x, y, z));
    let objects = [
        ("floor", "floor", t(0.0, -0.1, 0.0) * s(12.0, 0.2, 12.0)),
        ("back wall", "wall", t(0.0, 2.5, -6.1) * s(12.0, 5.0, 0.2)),
        ("left wall", "wall", t(-6.1, 2.5, 0.0) * s(0.2, 5.0, 12.0)),
        ("right wall", "wall", t(6.1, 2.5, 0.0) * s(0.2, 5.0, 12.0)),
    ];
    for (name, m, transform) in objects {
        b.place(name, cube, material(m), transform);
    }
}

/// The room's boxes and spheres (`material` names a material of
/// `materials/room.fx`).
fn place_room_props(
    b: &mut Builder,
    (cube, sphere): (usize, usize),
    material: impl Fn(&str) -> usize,
) {
    let s = |x: f32, y: f32, z: f32| Mat4::from_scale(Vec3::new(x, y, z));
    let t = |x: f32, y: f32, z: f32| Mat4::from_translation(Vec3::new(x, y, z));
    let turned = |angle: f32| Mat4::from_rotation_y(angle);
    let objects = [
        (
            "red box",
            cube,
            "red",
            t(-3.0, 0.75, -2.5) * s(1.5, 1.5, 1.5),
        ),
        (
            "tall box",
            cube,
            "white",
            t(3.2, 1.5, -3.0) * turned(0.5) * s(1.4, 3.0, 1.4),
        ),
        (
            "green box",
            cube,
            "green",
            t(0.5, 0.4, 2.0) * turned(-0.3) * s(2.0, 0.8, 1.0),
        ),
        (
            "blue sphere",
            sphere,
            "blue",
            t(-1.0, 1.0, -0.5) * s(1.0, 1.0, 1.0),
        ),
        (
            "gold sphere",
            sphere,
            "gold",
            t(2.0, 0.8, 0.5) * s(0.8, 0.8, 0.8),
        ),
        (
            "white sphere",
            sphere,
            "white",
            t(-3.5, 0.6, 1.5) * s(0.6, 0.6, 0.6),
        ),
        (
            "lamp",
            sphere,
            "lamp",
            t(0.0, 3.8, -4.5) * s(0.35, 0.35, 0.35),
        ),
        (
            "glass sphere",
            sphere,
            "glass",
            t(-1.2, 0.7, 2.6) * s(0.7, 0.7, 0.7),
        ),
    ];
    for (name, mesh, m, transform) in objects {
        b.place(name, mesh, material(m), transform);
    }
}

/// The room's lights: 24 coloured point lights on two rings (no shadows), a
/// spot light, a dim directional light and ambient light.
fn add_room_lights(b: &mut Builder) {
    for i in 0..24 {
        let a = i as f32 / 24.0 * std::f32::consts::TAU;
        let ring = if i % 2 == 0 { 4.2 } else { 2.6 };
        let pos = Vec3::new(
            a.cos() * ring,
            0.6 + 1.4 * ((i % 3) as f32),
            a.sin() * ring - 0.5,
        );
        let hue = i as f32 / 24.0;
        let color = Vec3::new(
            0.5 + 0.5 * (hue * std::f32::consts::TAU).cos(),
            0.5 + 0.5 * ((hue + 1.0 / 3.0) * std::f32::consts::TAU).cos(),
            0.5 + 0.5 * ((hue + 2.0 / 3.0) * std::f32::consts::TAU).cos(),
        );
        b.light(
            &format!("room point {i}"),
            Light {
                // 24 cube maps would be 144 layers: the key, spot and sun cast
                casts_shadows: false,
                ..Light::point(pos, color, 4.0 * PI, 6.0 + (i % 4) as f32)
            },
        );
    }
    b.light(
        "room spot",
        Light::spot(
            Vec3::new(0.0, 4.8, 0.5),
            Vec3::new(0.1, -1.0, -0.2),
            Vec3::new(1.0, 0.95, 0.8),
            3.0 * PI,
            7.0,
            0.35,
            0.5,
        ),
    );
    b.light(
        "room directional",
        Light::directional(
            Vec3::new(0.3, -1.0, -0.4),
            Vec3::new(0.9, 0.9, 1.0),
            0.25 * PI,
        ),
    );
    b.light("room ambient", Light::ambient(Vec3::ONE, 0.06));
}

/// `builtin:bench`: a 10×10 grid of tessellated spheres (960 triangles each) on a
/// subdivided floor, about 100K triangles, with only a dim ambient light (add
/// random point lights for benchmarks). One camera, "bench".
pub fn bench() -> Scene {
    let mut b = Builder::new("bench");
    let sphere = b.mesh(uv_sphere(32, 16));
    let floor = b.mesh(grid_plane(40));
    let mats = b.materials_from(BENCH_MATERIALS, "<builtin>/materials/bench.fx");
    let floor_m = mats["floor"];
    let mats: Vec<usize> = (0..8).map(|i| mats[&format!("bench_{i}")]).collect();
    b.place(
        "floor",
        floor,
        floor_m,
        Mat4::from_scale(Vec3::new(22.0, 1.0, 22.0)),
    );
    for j in 0..10 {
        for i in 0..10 {
            let p = Vec3::new(-9.0 + 2.0 * i as f32, 0.7, -9.0 + 2.0 * j as f32);
            b.place(
                &format!("sphere {i},{j}"),
                sphere,
                mats[(i + j * 3) % mats.len()],
                Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.7),
                    Quat::from_rotation_y(0.1 * (i * j) as f32),
                    p,
                ),
            );
        }
    }
    b.light("bench ambient", Light::ambient(Vec3::ONE, 0.04));
    b.camera(
        "bench",
        Vec3::new(0.0, 14.0, 16.0),
        Vec3::new(0.0, 0.0, 0.5),
        55.0,
        0.5,
        60.0,
    );
    b.scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_has_about_100k_triangles() {
        let s = bench();
        let t = s.triangle_count();
        assert!((90_000..=110_000).contains(&t), "{t}");
    }

    #[test]
    fn proxies_are_closed_and_outward() {
        for m in [icosphere(2), cone(16), box_mesh(Vec3::ONE)] {
            // signed volume > 0 for CCW-outside meshes
            let v: f32 = m
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let (a, b, c) = (
                        m.positions[t[0] as usize],
                        m.positions[t[1] as usize],
                        m.positions[t[2] as usize],
                    );
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            assert!(v > 0.0, "{}: volume {v}", m.name);
        }
        let r = inradius(&icosphere(2));
        assert!(r > 0.9 && r < 1.0, "{r}");
    }
}
