//! The effect in the viewer: what the panel's controls and `--view-do set`
//! change, through the library's one rule ([`Effect::set`], [`Effect::reset`]:
//! uniforms written, or the effect planned again). The command line's `--set`s
//! are compiled in as a normal run does; a reload keeps the pass parameters set
//! here where they still exist with the same type.

use crate::app::{Change, Effect, RunError};
use crate::gpu::executor::{ParamInfo, Prepared};
use crate::graph::{EffectParam, Graph, Override};
use crate::script::types::{format_value, ParamType};

/// The effect being viewed.
pub struct Fx {
    names: Vec<String>,
    /// `--set`s always given first and never shown (the default chain's settings).
    base: Vec<String>,
    /// `None` for a scene shown without effects.
    pub effect: Option<Effect>,
}

impl Fx {
    /// Compile `names` with `base` and the command line's `sets` exactly as a
    /// normal run does (its diagnostics are the same).
    pub fn new(names: &[String], base: &[String], sets: &[Override]) -> Result<Fx, RunError> {
        let effect = if names.is_empty() {
            None
        } else {
            let mut all = Override::parse_all(base);
            all.extend(sets.iter().cloned());
            Some(Effect::compile_overrides(names, all)?)
        };
        Ok(Fx {
            names: names.to_vec(),
            base: base.to_vec(),
            effect,
        })
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

    /// The effect names (for the title).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Compile the effect again with its settings (its files changed).
    pub fn compile(&self) -> Result<Effect, RunError> {
        match &self.effect {
            Some(e) => e.recompile(),
            None => Err(RunError::Other("no effect to compile".into())),
        }
    }

    /// The effect parameters, with their current values.
    pub fn effect_params(&self) -> &[EffectParam] {
        self.graph().map_or(&[], |g| &g.params)
    }

    /// Has the panel or the command line set this pass parameter?
    pub fn pass_is_set(&self, name: &str) -> bool {
        self.effect.as_ref().is_some_and(|e| e.pass_is_set(name))
    }

    /// The value a pass parameter goes back to on reset: the effect's.
    pub fn pass_default(&self, p: &ParamInfo) -> Vec<f64> {
        self.effect
            .as_ref()
            .map_or_else(|| p.value.clone(), |e| e.pass_default(p))
    }

    /// Set parameter `key` to `value` (a `--set` value text) ([`Effect::set`]).
    pub fn set(
        &mut self,
        prepared: Option<&mut Prepared>,
        key: &str,
        value: &str,
    ) -> Result<Change, String> {
        let effect = self.effect_mut().map_err(|e| e.to_string())?;
        effect.set(prepared, key, value).map_err(|e| e.to_string())
    }

    /// Set back to the effect's value ([`Effect::reset`]).
    pub fn reset(&mut self, prepared: Option<&mut Prepared>, key: &str) -> Result<Change, String> {
        let effect = self.effect_mut().map_err(|e| e.to_string())?;
        effect.reset(prepared, key).map_err(|e| e.to_string())
    }

    /// The values set, as command-line arguments (`--set KEY=VALUE ...`): the
    /// overrides (but the base ones), then the pass parameters by their shortest
    /// unique name.
    pub fn as_set_args(&self, params: &[ParamInfo]) -> String {
        let Some(effect) = &self.effect else {
            return String::new();
        };
        let mut args: Vec<String> = effect
            .overrides()
            .iter()
            .map(|o| o.arg().to_string())
            .filter(|a| !self.base.contains(a))
            .collect();
        for (name, value) in effect.pass_settings() {
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
                name.to_string()
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

/// An effect parameter's value as a `--set` writes it (ENUM by name, BOOL as a word).
pub fn effect_value_text(p: &EffectParam, value: &[f64]) -> String {
    match &p.ty {
        ParamType::Enum(names) => names
            .get(value[0] as usize)
            .cloned()
            .unwrap_or_else(|| format_value(value)),
        ParamType::Bool => (value[0] != 0.0).to_string(),
        _ => format_value(value),
    }
}
