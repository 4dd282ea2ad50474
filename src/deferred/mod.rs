//! The built-in deferred renderer: scenes in, a linear HDR image plus the G-buffer
//! images that effects read as `AUX.*` out.
//!
//! - [`scene`]: the scene model ([`Scene`], [`Camera`], [`Light`], [`Material`]),
//!   random lights and camera specs; [`builtin`] procedural scenes; [`gltf_load`]
//!   validated glTF 2.0 loading.
//! - [`renderer`]: [`Renderer`] with three techniques ([`Technique`]): deferred
//!   shading with the compressed G-buffer and light volumes (seed 001), light
//!   pre-pass (seed 000) and forward shading, plus forward transparency.
//! - [`normal`]: the two-channel normal encodings (octahedral, spheremap) on the CPU.
//! - [`gbuffer`]: [`write_gbuffer`], every G-buffer image as viewable files.
//! - [`bench`]: the technique benchmark (frame times vs light count).
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
mod frame;
pub mod gbuffer;
pub mod gltf_load;
mod gpu_types;
pub mod job;
mod lights;
pub mod material;
pub mod normal;
mod pipelines;
pub mod renderer;
pub mod scene;
pub mod targets;
mod upload;

pub use gbuffer::write_gbuffer;
pub use normal::NormalEncoding;
pub use renderer::{
    render, GBufferTextures, RenderError, RenderOutput, RenderStats, Renderer, RendererOptions,
    Technique,
};
pub use scene::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Scene, SceneError,
    ShaderBinding, TextureImage, ATTENUATION_THRESHOLD,
};
