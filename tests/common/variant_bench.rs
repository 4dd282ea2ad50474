//! The feature-selection benchmark (the materials-and-effects paper claims conditional compilation is
//! 1.5–2× faster than run-time branching): the same scene rendered with
//! preprocessor variants, override constants and run-time branches, per
//! technique; run by `bench/materials.sh`.
//!
//! One renderer per mode; each technique renders `warmup` frames per mode
//! (pipelines are compiled then), then `frames` rounds of one frame per mode in
//! turn; the median of the GPU time of the pass that runs the surface
//! shaders (deferred: `geometry`, forward: `forward`) and of the whole frame are
//! reported (GPU timestamps; CPU wall time to idle where the device has none).

use super::render_bench::median;
use fxgraph::gpu::context::{GpuContext, GpuTimer};
use fxgraph::render::material::VariantMode;
use fxgraph::render::renderer::{RenderError, Renderer, RendererOptions, Technique};
use fxgraph::scene::{Camera, Scene};
use std::fmt;
use std::time::Instant;

/// One measured configuration.
#[derive(Debug, Clone)]
pub struct VariantRow {
    pub mode: VariantMode,
    pub technique: Technique,
    /// Median GPU ms of the surface-shader pass.
    pub surface_pass_ms: f64,
    /// Median ms of the frame.
    pub frame_ms: f64,
    pub pipelines: usize,
    pub modules: usize,
}

/// The benchmark's result; `Display` prints a Markdown table.
#[derive(Debug, Clone)]
pub struct VariantReport {
    pub adapter: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub lights: usize,
    pub rows: Vec<VariantRow>,
}

/// Renders `scene` from `camera` in every mode and technique of the lists.
#[allow(clippy::too_many_arguments)]
pub fn run_variant_benchmark(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    (width, height): (u32, u32),
    modes: &[VariantMode],
    techniques: &[Technique],
    (warmup, frames): (usize, usize),
    mut progress: impl FnMut(&VariantRow),
) -> Result<VariantReport, RenderError> {
    let timer = GpuTimer::new(ctx, 16);
    let mut renderers = modes
        .iter()
        .map(|&mode| {
            Renderer::new(
                ctx,
                scene,
                &RendererOptions {
                    variants: mode,
                    ..Default::default()
                },
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut rows = Vec::new();
    for &technique in techniques {
        let pass = match technique {
            Technique::Deferred => "geometry",
            Technique::LightPrepass => "final geometry",
            Technique::Forward => "forward",
            other => {
                return Err(RenderError::Invalid(format!(
                    "no surface pass known for {other:?}"
                )))
            }
        };
        let mut surface = vec![Vec::new(); modes.len()];
        let mut frame = vec![Vec::new(); modes.len()];
        let mut last = vec![None; modes.len()];
        // Round-robin over the modes, so that drifts of the machine (other load,
        // clock) fall on every mode alike.
        for i in 0..warmup + frames {
            for (m, renderer) in renderers.iter_mut().enumerate() {
                let start = Instant::now();
                let (_, stats) =
                    renderer.render(ctx, camera, width, height, technique, timer.as_ref())?;
                ctx.wait_idle()?;
                let wall = start.elapsed().as_secs_f64() * 1e3;
                if i >= warmup {
                    frame[m].push(stats.gpu_ms.unwrap_or(wall));
                    if let Some((_, ms)) = stats.pass_ms.iter().find(|(n, _)| n == pass) {
                        surface[m].push(*ms);
                    }
                }
                last[m] = Some(stats);
            }
        }
        for (m, &mode) in modes.iter().enumerate() {
            let stats = last[m].take().expect("at least one frame");
            let row = VariantRow {
                mode,
                technique,
                surface_pass_ms: median(&mut surface[m]),
                frame_ms: median(&mut frame[m]),
                pipelines: stats.pipelines,
                modules: stats.shader_modules,
            };
            progress(&row);
            rows.push(row);
        }
    }
    Ok(VariantReport {
        adapter: format!("{} ({})", ctx.info.name, ctx.info.backend),
        scene: scene.name.clone(),
        width,
        height,
        frames,
        lights: scene.lights.len(),
        rows,
    })
}

impl fmt::Display for VariantReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} {}x{}, {} lights, {} (median of {} frames)\n",
            self.scene, self.width, self.height, self.lights, self.adapter, self.frames
        )?;
        writeln!(
            f,
            "| technique | mode | surface pass ms | frame ms | surface pass / preprocess | pipelines | shader modules |"
        )?;
        writeln!(f, "|---|---|---:|---:|---:|---:|---:|")?;
        for r in &self.rows {
            let base = self
                .rows
                .iter()
                .find(|b| b.technique == r.technique && b.mode == VariantMode::Preprocess)
                .map(|b| b.surface_pass_ms);
            let ratio = base
                .map(|b| format!("{:.2}x", r.surface_pass_ms / b))
                .unwrap_or_else(|| "-".into());
            writeln!(
                f,
                "| {} | {} | {:.1} | {:.1} | {ratio} | {} | {} |",
                r.technique, r.mode, r.surface_pass_ms, r.frame_ms, r.pipelines, r.modules
            )?;
        }
        Ok(())
    }
}
