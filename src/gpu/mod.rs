//! The GPU layer: device and adapter checks, transfers between images in memory and
//! textures, the pipeline cache and the executor that interprets a plan, and streams
//! of frames through it. No files: sources and sinks are the application's
//! ([`crate::app`]).
pub mod bindings;
pub mod compute_module;
pub mod context;
pub mod executor;
pub mod formats;
pub mod fullscreen;
pub mod stream;
pub mod transfer;
pub mod yuv;
