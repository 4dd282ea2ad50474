//! The renderer's and the scene's tests, one binary: each `tests/NAME.rs` listed
//! here is a module of it (`cargo test --test scene NAME::`). One binary instead
//! of one per file: linking each cost CI minutes. The files stay where they are.

#[path = "../common/mod.rs"]
mod common;

#[path = "../camera_cut.rs"]
mod camera_cut;
#[path = "../cascades.rs"]
mod cascades;
#[path = "../compute_lighting.rs"]
mod compute_lighting;
#[path = "../deferred.rs"]
mod deferred;
#[path = "../environment.rs"]
mod environment;
#[path = "../environment_bench.rs"]
mod environment_bench;
#[path = "../environment_scenes.rs"]
mod environment_scenes;
#[path = "../gltf_clearcoat.rs"]
mod gltf_clearcoat;
#[path = "../gltf_materials.rs"]
mod gltf_materials;
#[path = "../gltf_transmission.rs"]
mod gltf_transmission;
#[path = "../gpu_skinning.rs"]
mod gpu_skinning;
#[path = "../jitter.rs"]
mod jitter;
#[path = "../light_culling.rs"]
mod light_culling;
#[path = "../material_diagnostics.rs"]
mod material_diagnostics;
#[path = "../materials.rs"]
mod materials;
#[path = "../motion_vectors.rs"]
mod motion_vectors;
#[path = "../scene_animation.rs"]
mod scene_animation;
#[path = "../scene_animation_corpus.rs"]
mod scene_animation_corpus;
#[path = "../scene_fog.rs"]
mod scene_fog;
#[path = "../scene_sequences.rs"]
mod scene_sequences;
#[path = "../scene_skinning.rs"]
mod scene_skinning;
#[path = "../shadows.rs"]
mod shadows;
#[path = "../ssgi.rs"]
mod ssgi;
#[path = "../taa_scene.rs"]
mod taa_scene;
#[path = "../visibility_buffer.rs"]
mod visibility_buffer;
