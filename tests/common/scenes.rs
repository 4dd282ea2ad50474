//! Scenes shared by the renderer tests.
#![allow(dead_code)]

use fxgraph::scene::{AlphaMode, Scene};

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
