//! A compiled effect chain ([`Effect`]) and running it on an image in memory
//! ([`apply_in_memory`]): the library API for Rust programs and tests.
//!
//! - [`Effect::compile`]: compile effects (files or built-in names; no device needed).
//! - [`Effect::prepare`]: plan it for an input size/format and build its pipelines on
//!   an [`Engine`] (which may wrap the caller's own device:
//!   [`crate::gpu::context::GpuContext::from_existing`]).

use super::error::RunError;
use super::report::{ms, MemoryReport, RunReport};
use crate::gpu::context::GpuError;
use crate::gpu::executor::{Engine, ExecError, FrameInputs, Prepared};
use crate::gpu::transfer::{create_output, input_format, read_pixels, upload_image};
use crate::graph::plan::{plan, InputDesc, PlanOptions};
use crate::graph::Graph;
use crate::pixels::{Image, Pixels};
use crate::script::types::Format;
use crate::script::{Diagnostics, SourceMap};
use std::time::Instant;

/// A compiled effect chain.
pub struct Effect {
    pub graph: Graph,
    pub sources: SourceMap,
    /// Warnings and notes from compiling.
    pub warnings: Diagnostics,
}

impl Effect {
    /// Compile a chain of effects (paths or built-in names) with `NAME=VALUE` overrides.
    pub fn compile(effects: &[String], overrides: &[String]) -> Result<Effect, RunError> {
        let req = crate::lookup::DiskEffects::request(effects, overrides);
        let (graph, diags, sources) = crate::shader::compile_all(&req);
        match graph {
            Some(graph) if !diags.has_errors() => Ok(Effect {
                graph,
                sources,
                warnings: diags,
            }),
            _ => Err(RunError::Rejected {
                rendered: diags.render(&sources),
            }),
        }
    }

    /// Plan for `input` and prepare on `engine`; the output is rendered in
    /// `output_format` (None: the output pass's own format).
    pub fn prepare(
        &mut self,
        engine: &mut Engine,
        input: &InputDesc,
        output_format: Option<Format>,
    ) -> Result<Prepared, RunError> {
        let opts = PlanOptions {
            output_format,
            ..Default::default()
        };
        self.prepare_with(engine, input, &opts)
    }

    /// [`Effect::prepare`] with explicit plan options (e.g. `ReusePolicy::Pool` for
    /// streams, which keep their textures across frames).
    pub fn prepare_with(
        &mut self,
        engine: &mut Engine,
        input: &InputDesc,
        opts: &PlanOptions,
    ) -> Result<Prepared, RunError> {
        let (p, notes) = plan(&self.graph, input, opts).map_err(|d| RunError::Rejected {
            rendered: d.render(&self.sources),
        })?;
        self.warnings.extend(notes);
        engine
            .prepare(&self.graph, p, &mut self.sources)
            .map_err(|e| match e {
                ExecError::Rejected(d) => RunError::Rejected {
                    rendered: d.render(&self.sources),
                },
                ExecError::Gpu(g) => RunError::Gpu(g),
                ExecError::Input(s) => RunError::Other(s),
            })
    }
}

/// Apply an effect chain to an in-memory image on `engine`; returns the output
/// size and pixels read back in `out_format` (rgba8-srgb gives sRGB-encoded U8,
/// rgba16f/rgba32f give linear F32). Used by tests and Rust programs.
pub fn apply_in_memory(
    engine: &mut Engine,
    effects: &[String],
    overrides: &[String],
    img: &Image,
    aux: &[(String, &Image)],
    out_format: Format,
    assume_linear: bool,
) -> Result<(u32, u32, Pixels), RunError> {
    let mut effect = Effect::compile(effects, overrides)?;
    run_on_image(
        engine,
        &mut effect,
        img,
        aux,
        out_format,
        assume_linear,
        false,
        &mut RunReport::default(),
    )
}

/// Plan `effect` for `img`, upload it, run it once and read the output back,
/// recording the stage times (pipelines, upload, passes, readback) in `report`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_on_image(
    engine: &mut Engine,
    effect: &mut Effect,
    img: &Image,
    aux: &[(String, &Image)],
    out_format: Format,
    assume_linear: bool,
    timings: bool,
    report: &mut RunReport,
) -> Result<(u32, u32, Pixels), RunError> {
    let (in_format, in_cs) = input_format(img, assume_linear);
    let desc = InputDesc {
        width: img.width,
        height: img.height,
        format: in_format,
        colorspace: in_cs,
        aux: aux
            .iter()
            .map(|(n, a)| (n.clone(), input_format(a, assume_linear).0))
            .collect(),
    };
    let t = Instant::now();
    let mut prepared = effect.prepare(engine, &desc, Some(out_format))?;
    report.steps.pipeline_ms = ms(t.elapsed());
    report.plans += 1;
    report.memory = MemoryReport::of(&prepared.plan);
    let t = Instant::now();
    let ctx = engine.ctx.clone();
    let input_tex = upload_image(&ctx, "fxgraph input", img, in_format)?;
    let aux_tex: Vec<(String, wgpu::Texture)> = aux
        .iter()
        .map(|(n, a)| {
            Ok((
                n.clone(),
                upload_image(
                    &ctx,
                    &format!("aux {n}"),
                    a,
                    input_format(a, assume_linear).0,
                )?,
            ))
        })
        .collect::<Result<_, GpuError>>()?;
    let out = prepared.plan.output;
    let output_tex = create_output(&ctx, out.width, out.height, out.format);
    report.steps.upload_ms = ms(t.elapsed());
    let t = Instant::now();
    let mut inputs = FrameInputs::still(&input_tex, &prepared.plan);
    for (n, tex) in &aux_tex {
        inputs.aux.insert(n.clone(), tex.into());
    }
    report.passes = prepared.run(engine, &inputs, &output_tex, timings)?;
    report.steps.passes_ms = ms(t.elapsed());
    let t = Instant::now();
    let pixels = read_pixels(&ctx, &output_tex, out.format)?;
    report.steps.readback_ms = ms(t.elapsed());
    Ok((out.width, out.height, pixels))
}
