//! fxgraph: a declarative filter-graph post-processing engine.
//!
//! Layers, each depending only on the ones above it (docs/architecture.md has the
//! table and `tests/layers.rs` checks it):
//! - [`pixels`]: images in memory (plain values every layer may use) and sRGB
//!   conversions.
//! - [`unwind`]: catching a dependency's panic quietly (used by `io` and `scene`,
//!   the layers that call decoders and parsers of files).
//! - [`script`]: the EFFECT language (grammar, AST with spans, diagnostics). No GPU.
//! - [`graph`]: lowering to a petgraph DAG, size/format resolution, schedule and the
//!   texture lifetime plan, all plain data. No GPU.
//! - [`shader`]: WGSL loading, `#ifdef` preprocessing, naga reflection, and the
//!   rewrite of a fragment shader into a compute shader. No GPU.
//! - `slang` (feature `slang`): RetroArch slang presets lowered to an EFFECT
//!   script and WGSL passes through the librashader crates (docs/slang.md).
//! - [`lookup`]: finding effect scripts on disk (search folders, `INCLUDE`
//!   confinement), the policy `graph` takes as an [`graph::EffectSource`]. No GPU.
//! - `io` (feature `gpu`): image files (PNG, JPEG, EXR, ...) with atomic writes,
//!   sequences, y4m, video files through ffmpeg.
//! - `gpu` (feature `gpu`): device, texture pool, pipelines and the executor that
//!   interprets a [`graph::Plan`] as fragment passes or compute dispatches.
//! - `scene` (feature `gpu`): the scene model without the GPU (meshes, materials as
//!   data, lights, cameras, the glTF and built-in loaders).
//! - `render` (feature `gpu`): the deferred / light pre-pass / forward renderer that
//!   consumes a loaded scene and returns images (no file I/O: nothing from `io`).
//! - `app` (feature `gpu`): jobs joining sources, the effect on the GPU and sinks;
//!   one report type. `fxrun` is a command line over it.
//! - `view` (feature `view`): the reusable parts of `fxrun --view` (the
//!   parameter panel, what is shown, the image pass, the pass inspector, the fps
//!   readout, camera control, the cached egui panel), without a window system.
// No printing from the library: messages go through `log` (Cargo.toml's
// `[lints]` has the rules held on every target).
#![cfg_attr(not(test), deny(clippy::print_stdout, clippy::print_stderr))]

pub mod graph;
pub mod lookup;
pub mod pixels;
pub mod script;
pub mod shader;
#[cfg(feature = "slang")]
pub mod slang;
pub mod unwind;

#[cfg(feature = "gpu")]
pub mod app;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "gpu")]
pub mod io;
#[cfg(feature = "gpu")]
pub mod render;
#[cfg(feature = "gpu")]
pub mod scene;
#[cfg(feature = "view")]
pub mod view;
