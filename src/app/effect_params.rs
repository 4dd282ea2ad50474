//! Changing a compiled effect's parameters: [`Effect::set`] and
//! [`Effect::reset`], the one rule the CLI, `--watch`, the viewer and embedders
//! use, answering whether uniforms were written ([`Change::Uniforms`]) or the
//! effect must be planned again ([`Change::Replan`]).
//!
//! - A **pass parameter** (a shader's uniform field, `brightPass.threshold`) is
//!   changed with [`Prepared::set_param`]: no recompiling, no re-planning.
//! - An **effect parameter** (`gaussian_blur.sigma`, an `ENUM`, a `BOOL`) may feed
//!   uniforms, `#define`s or sizes, so the chain is compiled again with it as an
//!   override. When the new graph has the same passes, defines, sizes and formats
//!   (only uniform values differ) the changed values are written to the prepared
//!   effect (history kept); otherwise the new effect comes back to be planned
//!   (pipelines come from the engine's cache).
//!
//! Pass parameters set here survive planning again: [`Effect::prepare_with`]
//! applies them where the parameter still exists with the same type.

use super::effect::Effect;
use super::error::RunError;
use crate::gpu::executor::{param_matches, ParamInfo, Prepared};
use crate::graph::{Graph, Override};

/// What applying a change needs from the caller.
#[non_exhaustive]
pub enum Change {
    /// Uniform values were written to the prepared effect: the next frame shows
    /// the change.
    Uniforms,
    /// The effect's passes changed: plan this effect (it holds the change) in
    /// place of the old one, or drop it to keep the old one, unchanged.
    Replan(Box<Effect>),
}

/// The effect parameters a key names: `EFFECT.NAME`, or a bare `NAME`.
fn effect_params_of(graph: &Graph, key: &str) -> Vec<usize> {
    let (path, name) = match key.rsplit_once('.') {
        Some((p, n)) => (Some(p), n),
        None => (None, key),
    };
    graph
        .params
        .iter()
        .enumerate()
        .filter(|(_, p)| p.name == name && path.is_none_or(|e| e == p.effect))
        .map(|(i, _)| i)
        .collect()
}

/// What identifies a graph's passes apart from their uniform values.
fn structure(g: &Graph) -> Vec<String> {
    let mut out = vec![format!(
        "out {} history {} latency {}",
        g.label(g.output),
        g.history,
        g.latency
    )];
    for &n in &g.schedule {
        let p = g.pass(n);
        let inputs: Vec<String> = g
            .inputs_with_sources(n)
            .map(|(inp, src)| {
                format!(
                    "{}={} {:?} {:?}",
                    inp.name,
                    g.label(src),
                    inp.sampling,
                    inp.colorspace
                )
            })
            .collect();
        out.push(format!(
            "{} {} {:?} {:?} {:?} {:?} {}",
            p.path,
            p.shader,
            p.defines,
            p.size,
            p.format,
            p.colorspace,
            inputs.join(" ")
        ));
    }
    out
}

/// The pass parameter values of `new` that differ from `old` (same structure).
fn changed_values(old: &Graph, new: &Graph) -> Vec<(String, Vec<f64>)> {
    let mut out = Vec::new();
    for (&a, &b) in old.schedule.iter().zip(&new.schedule) {
        let (pa, pb) = (old.pass(a), new.pass(b));
        for q in &pb.params {
            let before = pa.params.iter().find(|x| x.name == q.name);
            if before.is_none_or(|x| x.value != q.value) {
                out.push((format!("{}.{}", pb.path, q.name), q.value.clone()));
            }
        }
    }
    out
}

impl Effect {
    /// Set parameter `key` to `value` (a `--set` value: `0.5`, `(1, 2)`, `true`,
    /// `aces`): an effect parameter (`EFFECT.NAME` or `NAME`) or a pass parameter
    /// (`PASS.NAME`, by its full or short path) on `prepared`. Nothing changes on
    /// an error.
    pub fn set(
        &mut self,
        prepared: Option<&mut Prepared>,
        key: &str,
        value: &str,
    ) -> Result<Change, RunError> {
        let arg = format!("{}={}", key.trim(), value.trim());
        self.set_override(prepared, Override::parse(&arg))
    }

    /// [`Effect::set`] with a parsed override.
    pub fn set_override(
        &mut self,
        prepared: Option<&mut Prepared>,
        o: Override,
    ) -> Result<Change, RunError> {
        let key = o.key().trim().to_string();
        if self.is_effect_param(&key) {
            let mut overrides = self.overrides_without(&key);
            overrides.push(o);
            return self.recompiled(prepared, overrides);
        }
        let numbers = o
            .value()
            .and_then(|v| v.numbers())
            .filter(|v| v.iter().all(|x| x.is_finite()))
            .ok_or_else(|| {
                let value = o.arg().split_once('=').map_or("", |(_, v)| v);
                RunError::Other(format!("`{value}`: expected numbers"))
            })?;
        let prepared = prepared.ok_or_else(|| RunError::Other("nothing is shown yet".into()))?;
        prepared
            .set_param(&key, &numbers)
            .map_err(|e| RunError::Other(e.to_string()))?;
        for p in prepared.params() {
            if param_matches(&p.name, &key) {
                self.settings
                    .pass_sets
                    .insert(p.name.clone(), (numbers.clone(), p.ty.clone()));
            }
        }
        Ok(Change::Uniforms)
    }

    /// Set back to the effect's value: an effect parameter (`EFFECT.NAME`) to its
    /// default, a pass parameter (full name) to what the effect gives it.
    pub fn reset(
        &mut self,
        prepared: Option<&mut Prepared>,
        key: &str,
    ) -> Result<Change, RunError> {
        let overrides = self.overrides_without(key);
        if overrides.len() != self.settings.overrides.len() {
            self.forget_pass_sets(key);
            return self.recompiled(prepared, overrides);
        }
        let prepared = prepared.ok_or_else(|| RunError::Other("nothing is shown yet".into()))?;
        let names: Vec<String> = self
            .settings
            .pass_sets
            .keys()
            .filter(|n| *n == key || param_matches(n, key))
            .cloned()
            .collect();
        for n in names {
            self.settings.pass_sets.remove(&n);
            if let Some(v) = self.settings.effect_values.get(&n) {
                prepared
                    .set_param(&n, v)
                    .map_err(|e| RunError::Other(e.to_string()))?;
            }
        }
        Ok(Change::Uniforms)
    }

    /// The overrides the chain is compiled with (`--set`s and effect parameters
    /// set), in order.
    pub fn overrides(&self) -> &[Override] {
        &self.settings.overrides
    }

    /// The pass parameters set with [`Effect::set`], by full name, with their values.
    pub fn pass_settings(&self) -> impl Iterator<Item = (&str, &[f64])> {
        self.settings
            .pass_sets
            .iter()
            .map(|(k, (v, _))| (k.as_str(), v.as_slice()))
    }

    /// Has this pass parameter (full name) been set, with [`Effect::set`] or an
    /// override?
    pub fn pass_is_set(&self, name: &str) -> bool {
        self.settings.pass_sets.contains_key(name)
            || self
                .settings
                .overrides
                .iter()
                .any(|o| !self.is_effect_param(o.key()) && param_matches(name, o.key()))
    }

    /// The value a pass parameter goes back to on [`Effect::reset`]: the effect's.
    pub fn pass_default(&self, p: &ParamInfo) -> Vec<f64> {
        self.settings
            .effect_values
            .get(&p.name)
            .cloned()
            .unwrap_or_else(|| p.value.clone())
    }

    /// Is `key` an effect parameter (`EFFECT.NAME` or `NAME`)?
    pub fn is_effect_param(&self, key: &str) -> bool {
        !effect_params_of(&self.graph, key).is_empty()
    }

    /// The overrides without those naming the parameter `key` names.
    fn overrides_without(&self, key: &str) -> Vec<Override> {
        let wanted = effect_params_of(&self.graph, key);
        self.settings
            .overrides
            .iter()
            .filter(|o| {
                let k = o.key().trim();
                let same_effect_param =
                    !wanted.is_empty() && effect_params_of(&self.graph, k) == wanted;
                let same_pass_param = wanted.is_empty() && (k == key || param_matches(key, k));
                !(k == key || same_effect_param || same_pass_param)
            })
            .cloned()
            .collect()
    }

    fn forget_pass_sets(&mut self, key: &str) {
        self.settings
            .pass_sets
            .retain(|n, _| !(n == key || param_matches(n, key)));
    }

    /// Compile the chain with `overrides`; write the change as uniforms when the
    /// passes are the same, or hand the new effect back for planning.
    fn recompiled(
        &mut self,
        prepared: Option<&mut Prepared>,
        overrides: Vec<Override>,
    ) -> Result<Change, RunError> {
        let mut new = Effect::compile_overrides(&self.settings.chain, overrides)?;
        new.settings.keep_pass_settings(&self.settings);
        let Some(prepared) = prepared else {
            return Ok(Change::Replan(Box::new(new)));
        };
        if structure(&self.graph) != structure(&new.graph) {
            return Ok(Change::Replan(Box::new(new)));
        }
        let changes = changed_values(&self.graph, &new.graph);
        // Check every value first, so that a refusal changes nothing.
        let known: Vec<String> = prepared.params().into_iter().map(|p| p.name).collect();
        if changes.iter().any(|(n, _)| !known.contains(n)) {
            return Ok(Change::Replan(Box::new(new)));
        }
        for (name, value) in &changes {
            if let Err(e) = prepared.set_param(name, value) {
                log::debug!("{name}: {e}: planning again");
                return Ok(Change::Replan(Box::new(new)));
            }
        }
        new.settings.effect_values = self.settings.effect_values.clone();
        for (name, value) in changes {
            new.settings.effect_values.insert(name, value);
        }
        // Pass parameters set by name win over the effect's values.
        for (name, (value, _)) in &new.settings.pass_sets {
            let _ = prepared.set_param(name, value);
        }
        *self = new;
        Ok(Change::Uniforms)
    }
}
