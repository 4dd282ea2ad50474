//! The real `fxrun` binary, one module per topic: analysis modes (`--check`,
//! `--plan`, `--dot`, `--list`, `--describe`, `--help`), rejected arguments, runs on
//! images (exit codes, atomic writes, rejected inputs), shader diagnostic snapshots,
//! scenes, paths it refuses to read, frame sequences and batches, y4m files (8 to 16
//! bits) and video files through ffmpeg.
//!
//! One test binary (each binary links wgpu, which costs a minute on a small machine);
//! run one topic with `cargo test --test cli analysis::`.

#[path = "../common/mod.rs"]
mod common;

mod analysis;
mod arguments;
mod batch;
mod confinement;
mod images;
mod scenes;
mod sequences;
mod shader_diagnostics;
mod video_audio;
mod video_files;
mod y4m_files;

/// True when GPU tests should run (an adapter, or FX_REQUIRE_GPU=1 which makes
/// its absence fail).
fn gpu() -> bool {
    common::engine().is_some()
}

/// The largest texture side of the test device, or `None` (GPU tests skipped).
fn device_limit() -> Option<u32> {
    common::engine().map(|e| e.ctx.device.limits().max_texture_dimension_2d)
}
