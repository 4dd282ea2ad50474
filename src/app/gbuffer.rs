//! `--gbuffer DIR`: the renderer's G-buffer images
//! ([`crate::render::gbuffer_images`]) written as viewable files.

use super::error::RunError;
use super::scene_errors::render_error;
use crate::gpu::context::GpuContext;
use crate::io::{save_image, IoError, SaveOptions};
use crate::render::{gbuffer_images, RenderError, RenderOutput};
use std::path::{Path, PathBuf};

/// What writing the G-buffer can fail with: reading it back or writing a file.
enum Failure {
    Render(RenderError),
    Io(IoError),
}

impl From<RenderError> for Failure {
    fn from(e: RenderError) -> Self {
        Failure::Render(e)
    }
}

/// Writes every G-buffer image of `output` (the render of `scene`) into `dir`
/// (created if missing; each file written atomically) and returns their paths;
/// the files are listed at [`crate::render::gbuffer_images`].
pub fn write_gbuffer(
    dir: &Path,
    output: &RenderOutput,
    ctx: &GpuContext,
    scene: &str,
) -> Result<Vec<PathBuf>, RunError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        RunError::from(IoError::Io {
            path: dir.to_path_buf(),
            source: e,
        })
    })?;
    let (w, h) = (output.width, output.height);
    let mut written = Vec::new();
    let result = gbuffer_images(output, ctx, |image| {
        let path = dir.join(image.name);
        let opts = SaveOptions {
            bit_depth: None,
            assume_linear: image.assume_linear,
        };
        save_image(&path, w, h, &image.pixels, &opts).map_err(Failure::Io)?;
        log::info!("wrote {}", path.display());
        written.push(path);
        Ok(())
    });
    match result {
        Ok(()) => Ok(written),
        Err(Failure::Render(e)) => Err(render_error(scene, e)),
        Err(Failure::Io(e)) => Err(RunError::from(e)),
    }
}
