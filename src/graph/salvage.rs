//! What can still be checked when an effect script has errors, so that one run
//! reports every problem at once (a misspelt `--set`, an unknown pass and a WGSL
//! type error together) instead of one stage per run.
//!
//! Lowering needs a valid script, so with script errors it does not run. Two checks
//! do not need it:
//! - `--set` names against the parameters and passes the loaded scripts declare
//!   (loosely: a name is only reported when nothing in any loaded effect could
//!   match it, so no error is invented for a script that is itself broken);
//! - the shaders the scripts name ([`shader_references`]), which the shader layer
//!   loads and validates on their own (`shader::load::check_references`).

use super::library::Loader;
use super::lower::ParsedOverride;
use crate::script::ast::{self, DefineArg, PassKind};
use crate::script::{Diagnostic, Diagnostics, Span};
use std::collections::HashSet;
use std::path::PathBuf;

/// A `SHADER.name` written in a loaded script, with where to look for it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ShaderReference {
    pub name: String,
    /// The folder of the script that names it (None: the built-in library).
    pub dir: Option<PathBuf>,
    /// `DEFINE` values that are known without lowering (literals and parameter
    /// defaults), sorted by name.
    pub defines: Vec<(String, i64)>,
    pub span: Span,
}

/// Every shader named by a pass of a loaded effect, once per (name, folder,
/// defines). A pass whose `DEFINE` depends on something unknown is left out (its
/// shader would be checked against values it never gets).
pub fn shader_references(loader: &Loader) -> Vec<ShaderReference> {
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for (mi, (_, module)) in loader.modules.iter().enumerate() {
        let dir = loader.module_dir(mi);
        for effect in &module.effects {
            'pass: for pass in &effect.passes {
                let PassKind::Shader(name) = &pass.kind else {
                    continue;
                };
                let mut defines = Vec::new();
                for d in &pass.defines {
                    let v = match &d.value.node {
                        DefineArg::Int(i) => *i,
                        DefineArg::Param(p) => {
                            match effect.params.iter().find(|q| q.name.node == p.node) {
                                Some(q) if q.default.len() == 1 && q.default[0].fract() == 0.0 => {
                                    q.default[0] as i64
                                }
                                _ => continue 'pass,
                            }
                        }
                    };
                    defines.push((d.name.node.clone(), v));
                }
                defines.sort();
                let r = ShaderReference {
                    name: name.node.clone(),
                    dir: dir.clone(),
                    defines,
                    span: name.span,
                };
                if seen.insert((r.name.clone(), r.dir.clone(), r.defines.clone())) {
                    out.push(r);
                }
            }
        }
    }
    out
}

/// Report `--set` names that no loaded effect declares, as lowering would.
pub(super) fn check_overrides(
    loader: &Loader,
    overrides: &[ParsedOverride],
    diags: &mut Diagnostics,
) {
    let mut params: Vec<&str> = Vec::new();
    let mut effects: Vec<(&str, Vec<&str>)> = Vec::new();
    let mut passes: HashSet<&str> = HashSet::new();
    for (_, module) in &loader.modules {
        for effect in &module.effects {
            let own: Vec<&str> = effect.params.iter().map(|p| p.name.node.as_str()).collect();
            params.extend(own.iter().copied());
            effects.push((effect.name.node.as_str(), own));
            passes.extend(effect.passes.iter().map(|p| p.name.node.as_str()));
        }
    }
    for o in overrides {
        // The node a path names: `glow`, `blurX`, `glow/blurX`, `glow#2`.
        let last = o.path.rsplit(['/', '.']).next().unwrap_or("");
        let last = last.split('#').next().unwrap_or("");
        let known = if o.path.is_empty() {
            params.contains(&o.name.as_str())
        } else if passes.contains(last) {
            // `pass.field`: only the shader knows its fields.
            true
        } else {
            effects
                .iter()
                .any(|(e, own)| *e == last && own.contains(&o.name.as_str()))
        };
        if known {
            continue;
        }
        let what = if o.path.is_empty() {
            o.name.clone()
        } else {
            format!("{}.{}", o.path, o.name)
        };
        let mut d = Diagnostic::error(format!(
            "`--set {what}`: no effect or pass parameter of that name"
        ))
        .at(o.key_span, "unknown parameter");
        if let Some(s) = ast::suggest(&o.name, params.iter().copied()) {
            d = d.note(format!("did you mean `{s}`?"));
        }
        diags.push(d);
    }
}
