//! Scenes shared by the renderer tests.
#![allow(dead_code)]

use fxgraph::scene::{AlphaMode, Instance, Material, Mesh, Scene};
use glam::Mat4;

/// The built-in room without its blended (transparent) objects: what every
/// technique renders alike (transparency is forward-shaded after the opaque pass).
pub fn opaque_room() -> Scene {
    let mut s = Scene::load("builtin:room").unwrap();
    let blend: Vec<bool> = s
        .materials
        .iter()
        .map(|m| m.alpha_mode == AlphaMode::Blend)
        .collect();
    s.instances.retain(|i| !blend[i.material]);
    s
}

/// The scene `scene` of one object, `object`: `mesh` drawn with `material` at
/// `transform`; no lights, no environment.
pub fn one_object(
    scene: impl Into<String>,
    object: &str,
    mesh: Mesh,
    material: Material,
    transform: Mat4,
) -> Scene {
    let mut s = Scene {
        name: scene.into(),
        ..Default::default()
    };
    s.meshes.push(mesh);
    s.materials.push(material);
    s.instances.push(Instance {
        name: object.into(),
        mesh: 0,
        material: 0,
        transform,
        ..Default::default()
    });
    s
}
