//! Y'CbCr frames converted on the device: the planes of a y4m frame (8 to 16 bits,
//! 4:2:0, 4:2:2, 4:4:4 or luma only, any matrix and range) go up as they are stored
//! and a compute pass makes the effect's input texels ([`PlanesToRgb`]); the
//! effect's output comes back as planes, made by the reverse pass ([`RgbToPlanes`])
//! and copied into reused read-back buffers ([`PendingPlanes`]).
//!
//! The layer knows no file format: a [`PlaneLayout`] is plain data (sizes, depth,
//! siting, the matrix's coefficients, the vertical chroma taps), made by the caller
//! from the stream's header with the CPU conversion's own tables, so both paths
//! resample chroma with the same filter at the same siting.
//!
//! Files: `layout` (the description and its uniform block), `to_rgb` with `upload`
//! (its ring of upload buffers), `from_rgb`;
//! the shaders are `shaders/yuv/`.

mod from_rgb;
mod layout;
mod to_rgb;
mod upload;

pub use from_rgb::{PendingPlanes, RgbToPlanes};
pub use layout::{ChromaSiting, DownTap, PlaneLayout, UpTap, YuvCoefficients};
pub use to_rgb::PlanesToRgb;

use super::context::{GpuContext, GpuError};

/// Why frames cannot be converted on this device, or a device failure.
#[derive(Debug, thiserror::Error)]
pub enum YuvGpuError {
    /// The device cannot serve this layout (its limits, its backend); the caller
    /// converts on the CPU instead.
    #[error("Y'CbCr conversion on the GPU unavailable: {0}")]
    Unavailable(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// The WGSL of one conversion: the shared parameter block, then the pass.
fn shader_source(pass: &str) -> String {
    format!(
        "{}\n{pass}",
        include_str!("../../../shaders/yuv/yuv_params.wgsl")
    )
}

/// The compute pipeline of pass `pass` (entry point `main`, layout from the
/// shader) and its bind group layout, made once per device.
fn compute_pipeline(
    ctx: &GpuContext,
    label: &str,
    pass: &str,
) -> Result<(wgpu::ComputePipeline, wgpu::BindGroupLayout), GpuError> {
    ctx.compute_pipeline(label, &shader_source(pass))
}

/// A buffer of `size` bytes (at least 4, rounded up to a multiple of 4).
fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(4).next_multiple_of(4),
        usage,
        mapped_at_creation: false,
    })
}

/// Check that a storage buffer of `size` bytes fits the device.
fn check_storage(ctx: &GpuContext, what: &str, size: u64) -> Result<(), YuvGpuError> {
    let limits = ctx.device.limits();
    let max = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    if size > max {
        return Err(YuvGpuError::Unavailable(format!(
            "{what} needs a storage buffer of {size} bytes, the device binds at most {max}"
        )));
    }
    Ok(())
}
