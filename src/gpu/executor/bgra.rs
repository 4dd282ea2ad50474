//! Outputs in the BGRA twin of the plan's 8-bit output format: `Bgra8UnormSrgb`
//! for `rgba8-srgb`, `Bgra8Unorm` for `rgba8`, the formats window surfaces usually
//! offer (lavapipe on X11 offers only these). The values are the same, the channels
//! are stored in another order, so the output can be copied into a surface texture
//! instead of drawn by a pass of its own. The passes that write the output get a
//! pipeline for the twin format the first time a frame records into one (cached on
//! the engine like every pipeline; the bind groups are shared, their layouts being
//! equal).

use super::record::GpuPass;
use super::{CachedPipeline, Engine, PipelineKey};
use crate::gpu::context::GpuError;
use crate::script::types::Sampling;
use crate::shader::Reflection;
use std::sync::Arc;

/// The BGRA twin of an 8-bit RGBA format, and the RGBA twin of a BGRA one.
pub fn bgra_twin(f: wgpu::TextureFormat) -> Option<wgpu::TextureFormat> {
    use wgpu::TextureFormat as T;
    match f {
        T::Rgba8Unorm => Some(T::Bgra8Unorm),
        T::Rgba8UnormSrgb => Some(T::Bgra8UnormSrgb),
        T::Bgra8Unorm => Some(T::Rgba8Unorm),
        T::Bgra8UnormSrgb => Some(T::Rgba8UnormSrgb),
        _ => None,
    }
}

/// Is `f` a BGRA format?
pub(super) fn is_bgra(f: wgpu::TextureFormat) -> bool {
    matches!(
        f,
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    )
}

/// What a pass writing the output needs to build its pipeline for the twin format.
pub(super) struct TwinPipeline {
    pub key: PipelineKey,
    pub reflection: Reflection,
    pub samplers: Vec<(u32, Sampling, bool)>,
    pub label: String,
    pub built: Option<Arc<CachedPipeline>>,
}

impl TwinPipeline {
    /// For a pass rendering to `key.target` (an 8-bit RGBA format) the caller's output.
    pub fn new(
        key: &PipelineKey,
        reflection: &Reflection,
        samplers: &[(u32, Sampling, bool)],
        label: &str,
    ) -> Option<TwinPipeline> {
        let target = bgra_twin(key.target)?;
        Some(TwinPipeline {
            key: PipelineKey {
                target,
                ..key.clone()
            },
            reflection: reflection.clone(),
            samplers: samplers.to_vec(),
            label: format!("{label} (BGRA output)"),
            built: None,
        })
    }
}

impl GpuPass {
    /// The pipeline for a frame whose output is in the BGRA twin format (`bgra`) or
    /// in the plan's.
    pub(super) fn pipeline_for(
        &mut self,
        engine: &mut Engine,
        bgra: bool,
    ) -> Result<Arc<CachedPipeline>, GpuError> {
        let Some(twin) = self.twin.as_mut().filter(|_| bgra) else {
            return self.pipeline.clone().ok_or_else(|| GpuError::Validation {
                what: self.path.clone(),
                message: "a compute pass has no render pipeline".into(),
            });
        };
        if let Some(p) = &twin.built {
            return Ok(p.clone());
        }
        let built = engine.pipeline(&twin.key, &twin.reflection, &twin.samplers, &twin.label)?;
        twin.built = Some(built.clone());
        Ok(built)
    }
}
