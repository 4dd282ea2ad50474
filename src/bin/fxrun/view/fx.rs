//! The effect in the viewer and its parameters: what the panel's controls and
//! `--view-do set` change, through one function ([`Fx::set`]).
//!
//! - A **pass parameter** (a shader's uniform field, `brightPass.threshold`) is
//!   changed with `Prepared::set_param`: no recompiling, no re-planning, the next
//!   frame shows it.
//! - An **effect parameter** (`gaussian_blur.sigma`, an `ENUM`, a `BOOL`) may feed
//!   uniforms, `#define`s or sizes, so the effect is compiled again with it as a
//!   `--set`. When the new graph has the same passes, defines, sizes and formats
//!   (only uniform values differ) the changed values are applied with `set_param`
//!   to the prepared effect (history kept); otherwise the caller plans again
//!   (pipelines come from the engine's cache).
//!
//! The command line's `--set` are split the same way: effect parameters are
//! compiled in, pass parameters set with `set_param` after every prepare, which
//! writes the same uniform bytes as compiling them in. A reload keeps the values
//! set here where the parameter still exists with the same type.

use fxgraph::app::{Effect, RunError};
use fxgraph::gpu::executor::{ParamInfo, Prepared};
use fxgraph::graph::{EffectParam, Graph};
use fxgraph::script::types::{format_value, ParamType};
use std::collections::BTreeMap;

/// What applying a change needs from the caller.
pub(super) enum Applied {
    /// Uniform values were written: the next frame shows the change.
    Uniforms,
    /// The effect's passes changed: put this effect in [`Fx::effect`] and plan it
    /// (or drop it to keep the current one).
    Replan(Box<Effect>),
}

/// The effect being viewed and the parameter values given to it.
pub(super) struct Fx {
    names: Vec<String>,
    /// `--set`s always given first and never shown (the default chain's settings).
    base: Vec<String>,
    /// Effect parameters set (command line, then panel): `KEY=VALUE` texts.
    effect_sets: Vec<(String, String)>,
    /// Pass parameters set, by full name (`glow/brightPass.threshold`), with the
    /// WGSL type they were set as.
    pass_sets: BTreeMap<String, (Vec<f64>, String)>,
    /// Pass parameter `--set`s of the command line not yet resolved to full names.
    pending_pass_sets: Vec<(String, Vec<f64>)>,
    /// `None` for a scene shown without effects.
    pub effect: Option<Effect>,
    /// The pass parameters as the effect gives them (before `pass_sets`).
    effect_values: BTreeMap<String, Vec<f64>>,
}

/// `0.5`, `(1, 2, 3)`, `1,2,3`, `true`, `false` as numbers.
pub(super) fn parse_numbers(text: &str) -> Option<Vec<f64>> {
    let t = text.trim();
    match t {
        "true" => return Some(vec![1.0]),
        "false" => return Some(vec![0.0]),
        _ => {}
    }
    let t = t
        .strip_prefix('(')
        .and_then(|x| x.strip_suffix(')'))
        .unwrap_or(t);
    let v: Option<Vec<f64>> = t.split(',').map(|x| x.trim().parse().ok()).collect();
    v.filter(|v| !v.is_empty() && v.iter().all(|x| x.is_finite()))
}

/// The effect parameters a `--set` key names: `EFFECT.NAME`, or a bare `NAME`.
pub(super) fn effect_params_of(graph: &Graph, key: &str) -> Vec<usize> {
    let (path, name) = match key.rfind('.') {
        Some(d) => (Some(&key[..d]), &key[d + 1..]),
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

/// An effect parameter's value as a `--set` writes it (ENUM by name, BOOL as a word).
pub(super) fn effect_value_text(p: &EffectParam, value: &[f64]) -> String {
    match &p.ty {
        ParamType::Enum(names) => names
            .get(value[0] as usize)
            .cloned()
            .unwrap_or_else(|| format_value(value)),
        ParamType::Bool => (value[0] != 0.0).to_string(),
        _ => format_value(value),
    }
}

/// Does a pass path match the part of a name before the dot (as `set_param`).
fn path_matches(path: &str, wanted: Option<&str>) -> bool {
    match wanted {
        None => true,
        Some(w) => path == w || path.rsplit('/').next() == Some(w),
    }
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

impl Fx {
    /// Compile `names` with `base` and the command line's `sets` exactly as a normal
    /// run does (its diagnostics are the same), then split the sets.
    pub fn new(names: &[String], base: &[String], sets: &[String]) -> Result<Fx, RunError> {
        if names.is_empty() {
            return Ok(Fx {
                names: Vec::new(),
                base: Vec::new(),
                effect_sets: Vec::new(),
                pass_sets: BTreeMap::new(),
                pending_pass_sets: Vec::new(),
                effect: None,
                effect_values: BTreeMap::new(),
            });
        }
        let all: Vec<String> = base.iter().chain(sets).cloned().collect();
        let full = Effect::compile(names, &all)?;
        let mut effect_sets = Vec::new();
        let mut pending_pass_sets = Vec::new();
        for s in sets {
            let (key, value) = s.split_once('=').unwrap_or((s, ""));
            let key = key.trim();
            if !effect_params_of(&full.graph, key).is_empty() {
                effect_sets.push((key.to_string(), value.trim().to_string()));
                continue;
            }
            match parse_numbers(value) {
                Some(v) => pending_pass_sets.push((key.to_string(), v)),
                // Not a plain number list: leave it to the compiler.
                None => effect_sets.push((key.to_string(), value.trim().to_string())),
            }
        }
        let mut fx = Fx {
            names: names.to_vec(),
            base: base.to_vec(),
            effect_sets,
            pass_sets: BTreeMap::new(),
            pending_pass_sets,
            effect: Some(full),
            effect_values: BTreeMap::new(),
        };
        fx.effect = Some(fx.compile()?);
        Ok(fx)
    }

    /// The compiled graph (none: a scene without effects).
    pub fn graph(&self) -> Option<&Graph> {
        self.effect.as_ref().map(|e| &e.graph)
    }

    /// The effect to plan.
    pub fn effect_mut(&mut self) -> Result<&mut Effect, RunError> {
        self.effect
            .as_mut()
            .ok_or_else(|| RunError::Other("no effect to plan".into()))
    }

    /// Does the effect read earlier output frames (feedback)?
    pub fn has_feedback(&self) -> bool {
        self.graph().is_some_and(|g| g.has_feedback())
    }

    /// Is `key` an effect parameter?
    fn is_effect_param(&self, key: &str) -> bool {
        self.graph()
            .is_some_and(|g| !effect_params_of(g, key).is_empty())
    }

    /// The effect parameters set, to put back with [`Fx::restore`] when a change
    /// could not be planned.
    pub fn snapshot(&self) -> Vec<(String, String)> {
        self.effect_sets.clone()
    }

    pub fn restore(&mut self, sets: Vec<(String, String)>) {
        self.effect_sets = sets;
    }

    /// The effect names (for the title).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Compile the effect with the base and the effect parameters set.
    pub fn compile(&self) -> Result<Effect, RunError> {
        if self.names.is_empty() {
            return Err(RunError::Other("no effect to compile".into()));
        }
        let sets: Vec<String> = self
            .base
            .iter()
            .cloned()
            .chain(self.effect_sets.iter().map(|(k, v)| format!("{k}={v}")))
            .collect();
        Effect::compile(&self.names, &sets)
    }

    /// After `prepared` was made from [`Fx::effect`]: note the values the effect gives
    /// and apply the pass parameters set. Returns the names set before that no
    /// longer exist (or changed type) and were dropped.
    pub fn after_prepare(&mut self, prepared: &mut Prepared) -> Vec<String> {
        let params = prepared.params();
        self.effect_values = params
            .iter()
            .map(|p| (p.name.clone(), p.value.clone()))
            .collect();
        for (key, value) in std::mem::take(&mut self.pending_pass_sets) {
            let (path, name) = match key.rfind('.') {
                Some(d) => (Some(&key[..d]), &key[d + 1..]),
                None => (None, key.as_str()),
            };
            for p in &params {
                let (ppath, pname) = p.name.rsplit_once('.').expect("PASS.NAME");
                if pname == name && path_matches(ppath, path) {
                    self.pass_sets
                        .insert(p.name.clone(), (value.clone(), p.ty.clone()));
                }
            }
        }
        // Values set survive where the name and the type are unchanged.
        let mut dropped = Vec::new();
        self.pass_sets.retain(|name, (value, ty)| {
            let ok = params.iter().any(|p| &p.name == name && &p.ty == ty)
                && prepared.set_param(name, value).is_ok();
            if !ok {
                dropped.push(name.clone());
            }
            ok
        });
        dropped
    }

    /// The effect parameters, with their current values.
    pub fn effect_params(&self) -> &[EffectParam] {
        self.graph().map_or(&[], |g| &g.params)
    }

    /// Has the panel or the command line set this pass parameter?
    pub fn pass_is_set(&self, name: &str) -> bool {
        self.pass_sets.contains_key(name)
    }

    /// The value a pass parameter goes back to on reset: the effect's.
    pub fn pass_default(&self, p: &ParamInfo) -> Vec<f64> {
        self.effect_values
            .get(&p.name)
            .cloned()
            .unwrap_or_else(|| p.value.clone())
    }

    /// Set parameter `key` to `value` (a `--set` value text) on `prepared`: a pass
    /// parameter by its full or short name, or an effect parameter
    /// (`EFFECT.NAME`). The one path of the panel's controls and `--view-do set`.
    pub fn set(
        &mut self,
        prepared: Option<&mut Prepared>,
        key: &str,
        value: &str,
    ) -> Result<Applied, String> {
        if self.is_effect_param(key) {
            let old = self.effect_sets.clone();
            self.forget_effect_param(key);
            self.effect_sets
                .push((key.to_string(), value.trim().to_string()));
            let result = self.recompile(prepared);
            if result.is_err() {
                self.effect_sets = old;
            }
            return result;
        }
        let numbers = parse_numbers(value).ok_or_else(|| format!("`{value}`: expected numbers"))?;
        let prepared = prepared.ok_or("nothing is shown yet")?;
        prepared
            .set_param(key, &numbers)
            .map_err(|e| e.to_string())?;
        let (path, name) = match key.rfind('.') {
            Some(d) => (Some(&key[..d]), &key[d + 1..]),
            None => (None, key),
        };
        for p in prepared.params() {
            let (ppath, pname) = p.name.rsplit_once('.').expect("PASS.NAME");
            if pname == name && path_matches(ppath, path) {
                self.pass_sets
                    .insert(p.name.clone(), (numbers.clone(), p.ty.clone()));
            }
        }
        Ok(Applied::Uniforms)
    }

    /// Set back to the effect's value: an effect parameter (`EFFECT.NAME`) to its
    /// default, a pass parameter (full name) to what the effect gives it.
    pub fn reset(&mut self, prepared: Option<&mut Prepared>, key: &str) -> Result<Applied, String> {
        if self.is_effect_param(key) {
            let old = self.effect_sets.clone();
            self.forget_effect_param(key);
            let result = self.recompile(prepared);
            if result.is_err() {
                self.effect_sets = old;
            }
            return result;
        }
        let prepared = prepared.ok_or("nothing is shown yet")?;
        let names: Vec<String> = self
            .pass_sets
            .keys()
            .filter(|n| *n == key || n.ends_with(&format!("/{key}")))
            .cloned()
            .collect();
        for n in names {
            self.pass_sets.remove(&n);
            if let Some(v) = self.effect_values.get(&n) {
                prepared.set_param(&n, v).map_err(|e| e.to_string())?;
            }
        }
        Ok(Applied::Uniforms)
    }

    /// Drop the `--set`s of the effect parameter `key` names.
    fn forget_effect_param(&mut self, key: &str) {
        let same: Vec<bool> = self
            .effect_sets
            .iter()
            .map(|(k, _)| k == key || self.same_effect_param(k, key))
            .collect();
        let mut i = 0;
        self.effect_sets.retain(|_| {
            i += 1;
            !same[i - 1]
        });
    }

    /// Do two `--set` keys name one effect parameter?
    fn same_effect_param(&self, a: &str, b: &str) -> bool {
        let Some(g) = self.graph() else {
            return false;
        };
        let (pa, pb) = (effect_params_of(g, a), effect_params_of(g, b));
        !pa.is_empty() && pa == pb
    }

    /// Compile with the effect parameters set; apply the change as uniforms when
    /// the passes are the same, or hand the new effect back for planning.
    fn recompile(&mut self, prepared: Option<&mut Prepared>) -> Result<Applied, String> {
        let new = self.compile().map_err(|e| e.to_string())?;
        let (Some(prepared), Some(old)) = (prepared, self.graph()) else {
            return Ok(Applied::Replan(Box::new(new)));
        };
        if structure(old) != structure(&new.graph) {
            return Ok(Applied::Replan(Box::new(new)));
        }
        let changes = changed_values(old, &new.graph);
        // Check every value first, so that a refusal changes nothing.
        let known: Vec<String> = prepared.params().into_iter().map(|p| p.name).collect();
        if changes.iter().any(|(n, _)| !known.contains(n)) {
            return Ok(Applied::Replan(Box::new(new)));
        }
        for (name, value) in &changes {
            if let Err(e) = prepared.set_param(name, value) {
                log::debug!("{name}: {e}: planning again");
                return Ok(Applied::Replan(Box::new(new)));
            }
            self.effect_values.insert(name.clone(), value.clone());
        }
        self.effect = Some(new);
        // Pass parameters set by name win over the effect's values.
        for (name, (value, _)) in &self.pass_sets {
            let _ = prepared.set_param(name, value);
        }
        Ok(Applied::Uniforms)
    }

    /// The values set, as command-line arguments (`--set KEY=VALUE ...`): the
    /// effect parameters, then the pass parameters by their shortest unique name.
    pub fn as_set_args(&self, params: &[ParamInfo]) -> String {
        let mut args: Vec<String> = self
            .effect_sets
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        for (name, (value, _)) in &self.pass_sets {
            let (path, field) = name.rsplit_once('.').expect("PASS.NAME");
            let short = path.rsplit('/').next().unwrap_or(path);
            let unique = params
                .iter()
                .filter(|p| {
                    p.name
                        .rsplit_once('.')
                        .is_some_and(|(pp, f)| f == field && pp.rsplit('/').next() == Some(short))
                })
                .count()
                == 1;
            let key = if unique {
                format!("{short}.{field}")
            } else {
                name.clone()
            };
            args.push(format!("{key}={}", format_value(value)));
        }
        args.iter()
            .map(|a| {
                if a.contains([' ', '(', ')']) {
                    format!("--set '{a}'")
                } else {
                    format!("--set {a}")
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

#[cfg(test)]
mod tests {
    use super::parse_numbers;

    #[test]
    fn set_values_parse_as_the_command_line_writes_them() {
        assert_eq!(parse_numbers("0.5"), Some(vec![0.5]));
        assert_eq!(parse_numbers("(1, 2, 3)"), Some(vec![1.0, 2.0, 3.0]));
        assert_eq!(parse_numbers("1,2"), Some(vec![1.0, 2.0]));
        assert_eq!(parse_numbers("true"), Some(vec![1.0]));
        assert_eq!(parse_numbers("aces"), None);
        assert_eq!(parse_numbers("nan"), None);
    }
}
