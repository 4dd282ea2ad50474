//! GPU tests of the built-in effects, one module per effect, against CPU oracles
//! (f64 implementations of the formulas documented in each effect's header; shared
//! ones in `oracle`), the G-buffer effects on synthetic G-buffers (`gbuffer`), the
//! temporal effects through the streaming runtime, and every effect at its defaults
//! on real photos (`defaults`).
//!
//! One test binary (each binary links wgpu, which costs a minute on a small
//! machine). Run with `FX_REQUIRE_GPU=1 XDG_RUNTIME_DIR=/tmp cargo test --test
//! effects`, one effect with `cargo test --test effects ssao::`; without an adapter
//! (and without FX_REQUIRE_GPU) the GPU tests skip. Measured values are printed
//! (`-- --nocapture`).

#[path = "../common/mod.rs"]
mod common;
mod oracle;

// Image effects.
mod bloom;
mod chroma_key;
mod color_grade;
mod edges;
mod format_convert;
mod fxaa;
mod gaussian_blur;
mod glow;
mod pencil;
mod sharpen;
mod tonemap;
mod vignette;

// G-buffer effects: ssao, dof, fog, outline.
mod gbuffer;

// Temporal effects, and those reading motion vectors.
mod auto_exposure;
mod chroma_key_temporal;
mod deinterlace;
mod frame_blend;
mod motion_blur;
mod motion_trail;
mod taa;
mod temporal_denoise;

// Every effect: plans, and the defaults on photos.
mod defaults;
mod plans;
