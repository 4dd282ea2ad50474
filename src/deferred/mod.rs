//! The built-in deferred renderer: scenes in, a linear HDR image plus the G-buffer
//! images that effects read as `AUX.*` out.
//!
//! - [`scene`]: the scene model ([`Scene`], meshes, instances, textures, random
//!   lights), its other parts in files of their own and re-exported there:
//!   `light.rs` ([`Light`]), `camera.rs` ([`Camera`], camera specs) and
//!   `material_model.rs` ([`Material`], [`ShaderBinding`]); [`builtin`] procedural
//!   scenes; [`gltf_load`] validated glTF 2.0 loading (nodes, meshes), with
//!   `gltf_material.rs` (materials, textures, `KHR_texture_transform`) and
//!   `gltf_lights_cameras.rs` (lights, cameras).
//! - [`material`]: the material system (seed 003, section 2): surface + lighting
//!   shaders per material, material files, the generated shaders (`shaders/`
//!   holds the templates) and the three variant modes (`docs/materials.md`).
//! - [`renderer`]: [`Renderer`] with three techniques ([`Technique`]): deferred
//!   shading with the compressed G-buffer and light volumes (seed 001), light
//!   pre-pass (seed 000) and forward shading, plus forward transparency. Its
//!   parts: `targets.rs` (G-buffer, light buffers, AUX images), `upload.rs`
//!   (geometry, textures, material bind groups), `lights.rs` (per-frame light
//!   lists, light volumes), `pipelines.rs` (layouts, module and pipeline caches),
//!   `frame.rs` (the passes of each technique), [`shadows`] (which lights get
//!   shadow maps, cascades, light matrices) and `shadow_pass.rs` (the shadow-map
//!   array and its depth pass), `gpu_types.rs`, `technique.rs`,
//!   `output.rs` ([`RenderOutput`], [`RenderStats`], [`published_aux`]).
//! - [`normal`]: the two-channel normal encodings (octahedral, spheremap) on the CPU.
//! - [`gbuffer`]: [`write_gbuffer`], every G-buffer image as viewable files.
//! - [`bench`]: the technique benchmark (frame times vs light count);
//!   [`variant_bench`]: the material variant-mode benchmark.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use fxgraph::deferred::{Renderer, RendererOptions, Scene, Technique};
//! use fxgraph::gpu::context::{AdapterChoice, GpuContext};
//! let ctx = GpuContext::new(&AdapterChoice::Auto)?;
//! let mut scene = Scene::load("builtin:room")?;
//! scene.add_random_point_lights(64, 1);
//! let camera = scene.default_camera();
//! let mut renderer = Renderer::new(&ctx, &scene, &RendererOptions::default())?;
//! let (out, stats) = renderer.render(&ctx, &camera, 640, 360, Technique::Deferred, None)?;
//! // out.scene: Rgba16Float linear HDR; out.aux: the AUX.* images; out.camera: CameraStd
//! # let _ = (out, stats); Ok(()) }
//! ```

pub mod bench;
pub mod builtin;
mod camera;
mod clusters;
pub mod fog;
mod frame;
pub mod gbuffer;
mod gltf_lights_cameras;
pub mod gltf_load;
mod gltf_material;
mod gpu_types;
mod light;
mod light_buffers;
mod lights;
pub mod material;
mod material_model;
pub mod normal;
mod output;
mod pipelines;
pub mod renderer;
pub mod scene;
mod shadow_pass;
pub mod shadows;
pub mod targets;
mod technique;
mod upload;
pub mod variant_bench;

pub use gbuffer::write_gbuffer;
pub use normal::NormalEncoding;
pub use output::published_aux;
pub use renderer::{
    render, GBufferTextures, RenderError, RenderOutput, RenderStats, Renderer, RendererOptions,
    Technique,
};
pub use scene::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Scene, SceneError,
    ShaderBinding, TextureImage, ATTENUATION_THRESHOLD,
};
pub use shadows::ShadowMode;
