//! The built-in renderer: a [`crate::scene::Scene`] in, a linear HDR image plus
//! the G-buffer images that effects read as `AUX.*` out.
//!
//! The scene model (meshes, materials as data, lights, cameras, loaders) lives in
//! `crate::scene`, without the GPU; this layer turns it into GPU work.
//!
//! - [`material`]: the material system (the materials-and-effects paper, section 2) on the renderer's
//!   side: surface + lighting shaders per material, the generated shaders
//!   (`shaders/` holds the templates) and the three variant modes
//!   (`docs/materials.md`).
//! - [`renderer`]: [`Renderer`] with three techniques ([`Technique`]): deferred
//!   shading with the compressed G-buffer and light volumes (Tang et al.), light
//!   pre-pass (the deferred-rendering survey) and forward shading, plus forward transparency. Its
//!   parts (imported top-down, no circle: `tests/layers.rs`): `error.rs`
//!   ([`RenderError`]), `options.rs` ([`RendererOptions`]), `targets.rs`
//!   (G-buffer, light buffers, AUX images), `upload/` (the scene uploaded once:
//!   `geometry.rs`, `textures.rs`, `materials.rs` for the material bind groups,
//!   `skinning.rs`: skinned and morphed vertices deformed on the GPU per frame
//!   from joints and weights), `frame_motion.rs`, `renderer_pose.rs` and
//!   `motion.rs` (a frame of a sequence: transforms, poses, camera cuts, motion
//!   vectors), `renderer_environment.rs` (the environment settings), `renderer_frame.rs`
//!   (the steps of a frame, from the cameras to the images handed back),
//!   `light_compute.rs` (the light pass in compute), `lights.rs` (per-frame light
//!   lists, light volumes), `light_buffers.rs`, `clusters.rs` (clustered light
//!   lists: the grid and the CPU reference), `cluster_gpu.rs` (the lists built
//!   on the GPU each frame), `pipelines.rs` (layouts, module and pipeline
//!   caches; `pass_states.rs`: what each pass and light pipeline renders into), `frame.rs` (the passes of each technique), [`shadows`] (which lights
//!   get shadow maps, cascades, light matrices) and `shadow_pass.rs` (the
//!   shadow-map array and its depth pass), [`fog`] (fog in the lighting template),
//!   `gpu_types.rs`, `technique.rs`, `output.rs` ([`RenderOutput`],
//!   [`RenderStats`], [`published_aux`]).
//! - [`environment`]: image-based lighting: the scene's environment map
//!   prefiltered on the GPU (GGX specular levels, irradiance, DFG table), the
//!   environment term of every material and the background.
//! - [`normal`]: the two-channel normal encodings (octahedral, spheremap) on the CPU.
//! - [`gbuffer`]: [`gbuffer_images`], every G-buffer image as a viewable image
//!   (`crate::app` writes them as files for `--gbuffer`).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use fxgraph::render::{Renderer, RendererOptions, Technique};
//! use fxgraph::scene::Scene;
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

mod camera_std;
mod cascades;
mod cli_names;
mod cluster_capacity;
mod cluster_gpu;
mod clusters;
pub mod environment;
mod error;
pub mod fog;
mod frame;
mod frame_motion;
mod frame_record;
pub mod gbuffer;
mod gbuffer_layout;
mod gpu_types;
mod light_buffers;
mod light_compute;
mod light_view_gpu;
mod lights;
pub mod material;
mod motion;
pub mod normal;
mod options;
mod output;
mod pass_states;
mod pipelines;
pub mod renderer;
mod renderer_environment;
mod renderer_frame;
mod renderer_lights;
mod renderer_pose;
mod shadow_cache;
mod shadow_pass;
pub mod shadows;
pub mod targets;
mod technique;
mod upload;
mod visibility;
mod visibility_pipelines;
mod visibility_shader;
mod wgsl_check;
mod world_lights;

pub use camera_std::camera_std;
pub use gbuffer::{gbuffer_images, GbufferImage};
pub use gbuffer_layout::GbufferLayout;
pub use normal::NormalEncoding;
pub use output::published_aux;
pub use renderer::{
    jittered, render, FrameMotion, GBufferTextures, RenderError, RenderOutput, RenderStats,
    Renderer, RendererOptions, Technique,
};
pub use shadows::ShadowMode;
pub use upload::skinning::DeformedVertices;
