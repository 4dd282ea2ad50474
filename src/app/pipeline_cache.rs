//! The GPU pipeline cache on disk, so that a second run starts warm: where the
//! backend has one (Vulkan's `VkPipelineCache`, wgpu's `PIPELINE_CACHE` feature),
//! the device's compiled pipelines are saved after a run and given back to the
//! next device on the same adapter and driver.
//!
//! - The file: `$FX_CACHE_DIR`, else `$XDG_CACHE_HOME/fxgraph`, else
//!   `$HOME/.cache/fxgraph`, named by wgpu's key for the adapter and driver
//!   (`wgpu::util::pipeline_cache_key`); a driver update makes a new key.
//! - `FX_PIPELINE_CACHE=0` turns it off. A missing, unreadable or foreign file is
//!   ignored (the driver validates the data and starts empty); a failed save is
//!   logged, never an error of the run. Writes are atomic.
//!
//! The device layer holds the cache ([`GpuContext::attach_pipeline_cache`]); the
//! files are this layer's, as the device layer reads none.

use crate::gpu::context::GpuContext;
use std::path::PathBuf;

/// Whether the cache is on (`FX_PIPELINE_CACHE` is not `0`).
fn enabled() -> bool {
    std::env::var("FX_PIPELINE_CACHE").map_or(true, |v| v.trim() != "0")
}

/// The folder of cache files.
fn folder() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("FX_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("fxgraph")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("fxgraph")))
}

/// The cache file of this context's adapter and driver, when it has a cache.
fn file(ctx: &GpuContext) -> Option<PathBuf> {
    if !enabled() || !ctx.has_pipeline_cache_feature() {
        return None;
    }
    Some(folder()?.join(ctx.pipeline_cache_key()?))
}

/// Give the device the pipelines a previous run saved (or an empty cache).
pub fn attach(ctx: &mut GpuContext) {
    let Some(path) = file(ctx) else { return };
    let data = std::fs::read(&path).ok();
    log::debug!(
        "pipeline cache {}: {} bytes",
        path.display(),
        data.as_ref().map_or(0, Vec::len)
    );
    ctx.attach_pipeline_cache(data.as_deref());
}

/// Save the device's pipeline cache for the next run.
pub fn save(ctx: &GpuContext) {
    let (Some(path), Some(data)) = (file(ctx), ctx.pipeline_cache_data()) else {
        return;
    };
    if std::fs::read(&path).is_ok_and(|old| old == data) {
        return;
    }
    let written = path
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .map_err(|e| e.to_string())
        .and_then(|()| {
            crate::io::write_atomic(&path, |w| {
                std::io::Write::write_all(w, &data).map_err(|source| crate::io::IoError::Io {
                    path: path.clone(),
                    source,
                })
            })
            .map_err(|e| e.to_string())
        });
    match written {
        Ok(()) => log::debug!(
            "pipeline cache saved: {} ({} bytes)",
            path.display(),
            data.len()
        ),
        Err(e) => log::info!("pipeline cache not saved: {e}"),
    }
}
