//! Parameters changed between frames without recompiling: [`Prepared::set_param`]
//! checks a value as a `--set` is checked at compile time (the shader's type and
//! `// @range`, `shader::check_member_value`) and writes only the pass's uniform
//! buffer.

use super::record::Prepared;
use crate::script::types::format_value;
use crate::shader::reflect::UniformSource;
use crate::shader::{check_member_value, ValueMismatch};

/// Why [`Prepared::set_param`] refused a value. Nothing is changed on an error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// No pass of the effect has this parameter.
    #[error("no pass parameter `{name}`{}", .suggestion.as_ref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default())]
    Unknown {
        name: String,
        suggestion: Option<String>,
    },
    /// A standard value (`frame`, `out_size`, ...), which the runtime sets.
    #[error("`{name}` is a standard value set by the runtime")]
    Standard { name: String },
    /// Wrong number of components, or a fraction (or a negative) for an integer field.
    #[error("wrong type for `{name}`: the shader declares {expected}, found {found}")]
    WrongType {
        name: String,
        expected: String,
        found: String,
    },
    /// Outside the field's `// @range(min, max)`.
    #[error("value {value} of `{name}` is out of range [{lo}, {hi}]")]
    OutOfRange {
        name: String,
        value: String,
        lo: f64,
        hi: f64,
    },
}

/// A parameter that [`Prepared::set_param`] accepts.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamInfo {
    /// `PASS_PATH.NAME`, e.g. `glow/blurX.sigma`.
    pub name: String,
    /// WGSL type, e.g. `f32`, `vec3<f32>`.
    pub ty: String,
    pub value: Vec<f64>,
    pub range: Option<(f64, f64)>,
    /// The shader's `// @default(...)`, if it has one (the value the pass gets
    /// when neither the effect nor `--set` gives one).
    pub default: Option<Vec<f64>>,
    /// The text of the field's comment after its annotations.
    pub description: String,
}

/// Does a pass path match the part of a parameter name before the dot: the whole
/// path (`glow/blurX`) or its last part (`blurX`), as with `--set`.
fn path_matches(path: &str, wanted: Option<&str>) -> bool {
    match wanted {
        None => true,
        Some(w) => path == w || path.rsplit('/').next() == Some(w),
    }
}

/// Does `key` (`PASS.NAME`, `glow/blurX.NAME` or a bare `NAME`, as
/// [`Prepared::set_param`] takes it) name the pass parameter `full`
/// (`PASS_PATH.NAME`, [`ParamInfo::name`])? The one rule of the library.
pub fn param_matches(full: &str, key: &str) -> bool {
    let Some((path, name)) = full.rsplit_once('.') else {
        return false;
    };
    match key.rsplit_once('.') {
        Some((wanted, n)) => n == name && path_matches(path, Some(wanted)),
        None => key == name,
    }
}

impl Prepared {
    /// The parameters of every pass, with their current values.
    pub fn params(&self) -> Vec<ParamInfo> {
        let mut out = Vec::new();
        for gp in &self.passes {
            let Some(u) = &gp.uniform else { continue };
            for f in &u.layout.fields {
                let UniformSource::Param(v) = &f.source else {
                    continue;
                };
                let m = u.members.iter().find(|m| m.name == f.name);
                out.push(ParamInfo {
                    name: format!("{}.{}", gp.path, f.name),
                    ty: f.ty.wgsl(),
                    value: v.clone(),
                    range: m.and_then(|m| m.range),
                    default: m.and_then(|m| m.default.clone()),
                    description: m.map(|m| m.description.clone()).unwrap_or_default(),
                });
            }
        }
        out
    }

    /// Set a shader parameter for the following frames, without recompiling.
    ///
    /// `name` is `PASS.NAME` (`blurX.sigma`, or the full path `glow/blurX.sigma`),
    /// or a bare `NAME` for every pass that has it. The value is checked against
    /// the shader's declaration as a `--set` is (component count, integer types,
    /// `// @range`); then the uniform buffers of the passes concerned are written
    /// (with `Queue::write_buffer`: the value takes effect at the next submission).
    /// Parameters of an effect (those its passes' bindings refer to) are resolved
    /// when the effect is compiled: set the pass parameters they feed instead.
    pub fn set_param(&mut self, name: &str, value: &[f64]) -> Result<(), ParamError> {
        let (path, pname) = match name.rfind('.') {
            Some(d) => (Some(&name[..d]), &name[d + 1..]),
            None => (None, name),
        };
        // Check every target first, so an error changes nothing.
        let mut targets = Vec::new();
        let mut standard = false;
        for (pi, gp) in self.passes.iter().enumerate() {
            if !path_matches(&gp.path, path) {
                continue;
            }
            let Some(u) = &gp.uniform else { continue };
            let Some(fi) = u.layout.fields.iter().position(|f| f.name == pname) else {
                continue;
            };
            if matches!(u.layout.fields[fi].source, UniformSource::Std(_)) {
                standard = true;
                continue;
            }
            let Some(m) = u.members.iter().find(|m| m.name == pname) else {
                continue;
            };
            check_member_value(m, value).map_err(|e| match e {
                ValueMismatch::WrongType { expected, found } => ParamError::WrongType {
                    name: name.to_string(),
                    expected,
                    found,
                },
                ValueMismatch::OutOfRange { value, lo, hi } => ParamError::OutOfRange {
                    name: name.to_string(),
                    value,
                    lo,
                    hi,
                },
            })?;
            targets.push((pi, fi));
        }
        if targets.is_empty() {
            if standard {
                return Err(ParamError::Standard {
                    name: name.to_string(),
                });
            }
            let names: Vec<String> = self.params().into_iter().map(|p| p.name).collect();
            let short: Vec<String> = names
                .iter()
                .map(|n| match n.rsplit_once('/') {
                    Some((_, s)) => s.to_string(),
                    None => n.clone(),
                })
                .collect();
            let suggestion = crate::script::ast::suggest(
                name,
                names.iter().chain(short.iter()).map(String::as_str),
            );
            return Err(ParamError::Unknown {
                name: name.to_string(),
                suggestion,
            });
        }
        for (pi, fi) in targets {
            let u = self.passes[pi].uniform.as_mut().expect("checked above");
            u.layout.fields[fi].source = UniformSource::Param(value.to_vec());
            let bytes = u.layout.write(&u.std);
            if bytes != u.written {
                self.queue.write_buffer(&u.buffer, 0, &bytes);
                u.written = bytes;
                self.stats.uniform_writes += 1;
            }
        }
        log::debug!("parameter {name} = {}", format_value(value));
        Ok(())
    }
}
