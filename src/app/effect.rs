//! A compiled effect chain ([`Effect`]): the library API for Rust programs and
//! tests (running it on an image in memory: [`super::apply_in_memory`]).
//!
//! - [`Effect::compile`]: compile effects (files or built-in names; no device needed)
//!   with `--set` overrides, parsed once ([`Override`]).
//! - [`Effect::set`]: change a parameter (`effect_params.rs`: the one rule for
//!   the CLI, `--watch`, the viewer and embedders).
//! - [`Effect::prepare`]: plan it for an input size/format and build its pipelines on
//!   an [`Engine`] (which may wrap the caller's own device:
//!   [`crate::gpu::context::GpuContext::from_existing`]).

use super::effect_settings::Settings;
use super::error::RunError;
use crate::gpu::executor::{Engine, ExecError, Prepared};
use crate::graph::plan::{plan, InputDesc, PlanOptions};
use crate::graph::{Graph, Override};
use crate::script::types::Format;
use crate::script::{Diagnostics, SourceMap};
use crate::shader::{preload_graph_shaders, ShaderCache};

/// A compiled effect chain, with the settings it was compiled with (kept for
/// [`Effect::set`]).
pub struct Effect {
    pub graph: Graph,
    pub sources: SourceMap,
    /// Warnings and notes from compiling.
    pub warnings: Diagnostics,
    pub(super) settings: Settings,
    /// Shaders loaded ahead ([`Effect::preload_shaders`]) for the next prepare.
    preloaded: Option<ShaderCache>,
}

impl Effect {
    /// Compile a chain of effects (paths or built-in names) with `NAME=VALUE`
    /// overrides (each parsed once, [`Override::parse`]).
    pub fn compile(effects: &[String], overrides: &[String]) -> Result<Effect, RunError> {
        Effect::compile_overrides(effects, Override::parse_all(overrides))
    }

    /// [`Effect::compile`] with overrides parsed already.
    pub fn compile_overrides(
        effects: &[String],
        overrides: Vec<Override>,
    ) -> Result<Effect, RunError> {
        let req = crate::lookup::DiskEffects::request_with(effects, overrides);
        let (graph, diags, sources) = crate::shader::compile_all(&req);
        match graph {
            Some(graph) if !diags.has_errors() => Ok(Effect {
                graph,
                sources,
                warnings: diags,
                settings: Settings::new(req.effects, req.overrides),
                preloaded: None,
            }),
            _ => Err(RunError::Rejected {
                rendered: diags.render(&sources),
            }),
        }
    }

    /// Compile the chain again with the same settings (its files changed).
    pub fn recompile(&self) -> Result<Effect, RunError> {
        let mut new =
            Effect::compile_overrides(&self.settings.chain, self.settings.overrides.clone())?;
        new.settings.keep_pass_settings(&self.settings);
        Ok(new)
    }

    /// The effects of the chain (paths or built-in names), in order.
    pub fn chain(&self) -> &[String] {
        &self.settings.chain
    }

    /// The sub-pixel jitter the chain asks its input frames to be rendered with
    /// (an effect declares `JITTER = halton23`), or `None`; see
    /// [`crate::gpu::executor::FrameInputs::jitter`].
    pub fn jitter(&self) -> Option<crate::script::JitterPattern> {
        self.graph.jitter
    }

    /// Load and reflect the shaders of the chain's passes now, for the next
    /// prepare to find (it loads what is missing, and reports every problem):
    /// needs no device, so a run does it while its device is created.
    pub fn preload_shaders(&mut self) {
        let mut cache = ShaderCache::default();
        preload_graph_shaders(&self.graph, &mut self.sources, &[], &mut cache);
        self.preloaded = Some(cache);
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
    /// streams, which keep their textures across frames). The pass parameters
    /// set with [`Effect::set`] are applied to the prepared effect.
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
        let mut cache = self.preloaded.take().unwrap_or_default();
        let mut prepared = engine
            .prepare_cached(&self.graph, p, &mut self.sources, &mut cache)
            .map_err(|e| match e {
                ExecError::Rejected(d) => RunError::Rejected {
                    rendered: d.render(&self.sources),
                },
                ExecError::Gpu(g) => RunError::Gpu(g),
                ExecError::Input(s) => RunError::Other(s),
            })?;
        self.settings.apply(&mut prepared);
        Ok(prepared)
    }
}
