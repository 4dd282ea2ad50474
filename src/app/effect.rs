//! A compiled effect chain ([`Effect`]): the library API for Rust programs and
//! tests (running it on an image in memory: [`super::apply_in_memory`]).
//!
//! - [`Effect::compile`]: compile effects (files or built-in names; no device needed).
//! - [`Effect::prepare`]: plan it for an input size/format and build its pipelines on
//!   an [`Engine`] (which may wrap the caller's own device:
//!   [`crate::gpu::context::GpuContext::from_existing`]).

use super::error::RunError;
use crate::gpu::executor::{Engine, ExecError, Prepared};
use crate::graph::plan::{plan, InputDesc, PlanOptions};
use crate::graph::Graph;
use crate::script::types::Format;
use crate::script::{Diagnostics, SourceMap};

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

    /// The sub-pixel jitter the chain asks its input frames to be rendered with
    /// (an effect declares `JITTER = halton23`), or `None`; see
    /// [`crate::gpu::executor::FrameInputs::jitter`].
    pub fn jitter(&self) -> Option<crate::script::JitterPattern> {
        self.graph.jitter
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
