//! `--set TARGET=VALUE`, parsed once where it enters ([`Override::parse`]) into a
//! typed target and value that keep their spans; the compiler, the CLI, `--watch`,
//! the viewer and embedders all read the same [`Override`].
//!
//! A malformed argument is kept with its diagnostic, which the compiler reports
//! with the others of the run (one report: a misspelt `--set` and a WGSL error
//! come back together).

use crate::script::parse::{parse_value, RawValue};
use crate::script::{Diagnostic, Diagnostics, FileId, Span, Spanned};

/// What a parameter may be set to.
#[derive(Debug, Clone, PartialEq)]
pub enum SetValue {
    /// A number or a tuple of numbers: `0.5`, `(1, 2, 3)`.
    Numbers(Vec<f64>),
    /// `true` or `false`.
    Bool(bool),
    /// One word: an `ENUM` value (`aces`).
    Word(String),
}

impl SetValue {
    /// The value as numbers (`true` is 1, `false` 0); `None` for a word.
    pub fn numbers(&self) -> Option<Vec<f64>> {
        match self {
            SetValue::Numbers(v) => Some(v.clone()),
            SetValue::Bool(b) => Some(vec![f64::from(u8::from(*b))]),
            SetValue::Word(_) => None,
        }
    }

    /// A parsed value as a parameter value; `None` for what no parameter takes
    /// (a string, a block, `IN[-1]`, a tuple of words).
    fn from_raw(v: &RawValue) -> Option<SetValue> {
        match v {
            RawValue::Number(n) => Some(SetValue::Numbers(vec![*n])),
            RawValue::Tuple(items) => items
                .iter()
                .map(|i| match i.node {
                    RawValue::Number(n) => Some(n),
                    _ => None,
                })
                .collect::<Option<Vec<f64>>>()
                .map(SetValue::Numbers),
            RawValue::Ref { key, frame: None } if key.is(&["true"]) => Some(SetValue::Bool(true)),
            RawValue::Ref { key, frame: None } if key.is(&["false"]) => Some(SetValue::Bool(false)),
            RawValue::Ref { key, frame: None } if key.parts.len() == 1 => {
                Some(SetValue::Word(key.first().to_string()))
            }
            _ => None,
        }
    }
}

/// The parsed parts of a well-formed `--set`; spans are in the argument's own
/// text (file [`Override::FILE`] until the compiler adds the text to its map).
#[derive(Debug, Clone)]
struct Parsed {
    path: String,
    name: String,
    key_span: Span,
    /// `None`: a value no parameter takes (reported where it is applied).
    value: Spanned<Option<SetValue>>,
}

/// `--set TARGET=VALUE`: TARGET is an effect parameter (`sigma`, `glow.strength`)
/// or a pass parameter (`blurX.radius`, `glow/blurX.radius`).
#[derive(Debug, Clone)]
pub struct Override {
    /// The whole argument, `TARGET=VALUE` (shown in diagnostics).
    arg: String,
    parsed: Result<Parsed, Vec<Diagnostic>>,
}

impl Override {
    /// The file id the spans of a parsed override use (its own text).
    const FILE: FileId = FileId(0);

    /// Parse `TARGET=VALUE`. Never fails: a malformed argument keeps its
    /// diagnostics for the compiler to report ([`Override::is_valid`]).
    pub fn parse(arg: &str) -> Override {
        Override {
            arg: arg.to_string(),
            parsed: Self::parse_parts(arg),
        }
    }

    /// [`Override::parse`] of each argument.
    pub fn parse_all<S: AsRef<str>>(args: &[S]) -> Vec<Override> {
        args.iter().map(|a| Override::parse(a.as_ref())).collect()
    }

    fn parse_parts(arg: &str) -> Result<Parsed, Vec<Diagnostic>> {
        let file = Self::FILE;
        let Some(eq) = arg.find('=') else {
            return Err(vec![Diagnostic::error(format!(
                "`--set {arg}` needs a value"
            ))
            .at(Span::new(file, 0, arg.len()), "expected NAME=VALUE")]);
        };
        let target = &arg[..eq];
        let (path, name) = match target.rfind('.') {
            Some(dot) => (target[..dot].to_string(), target[dot + 1..].to_string()),
            None => (String::new(), target.to_string()),
        };
        let key_span = Span::new(file, 0, eq);
        if name.is_empty() {
            return Err(vec![
                Diagnostic::error("`--set` needs a parameter name").at(key_span, "empty name")
            ]);
        }
        let mut diags = Diagnostics::default();
        let Some(value) = parse_value(file, arg, eq + 1, &mut diags) else {
            return Err(diags.list);
        };
        Ok(Parsed {
            path,
            name,
            key_span,
            value: Spanned::new(SetValue::from_raw(&value.node), value.span),
        })
    }

    /// The argument as given, `TARGET=VALUE`.
    pub fn arg(&self) -> &str {
        &self.arg
    }

    /// Is the argument well formed (`NAME=VALUE` with a value that parses)?
    pub fn is_valid(&self) -> bool {
        self.parsed.is_ok()
    }

    /// TARGET, as given (`glow.strength`); empty when malformed.
    pub fn key(&self) -> &str {
        self.arg.split_once('=').map_or("", |(k, _)| k)
    }

    /// The part of TARGET before its last dot (`glow/blurX`, `glow`; empty for a
    /// bare name or a malformed argument).
    pub fn path(&self) -> &str {
        self.parsed.as_ref().map_or("", |p| p.path.as_str())
    }

    /// The parameter's name (after the last dot of TARGET).
    pub fn name(&self) -> &str {
        self.parsed.as_ref().map_or("", |p| p.name.as_str())
    }

    /// The value; `None` when malformed or not a parameter value.
    pub fn value(&self) -> Option<&SetValue> {
        self.parsed
            .as_ref()
            .ok()
            .and_then(|p| p.value.node.as_ref())
    }

    /// Does this override name the parameter `key` names (`EFFECT.NAME`,
    /// `PASS.NAME` or a bare `NAME`, compared as written)?
    pub fn same_key(&self, key: &str) -> bool {
        self.key() == key
    }

    /// The parts with their spans moved to `file` (the override's text in the
    /// compiler's source map), or the diagnostics of a malformed argument.
    pub(crate) fn in_file(&self, file: FileId) -> Result<InFile, Vec<Diagnostic>> {
        let move_span = |s: Span| Span { file, ..s };
        match &self.parsed {
            Ok(p) => Ok(InFile {
                path: p.path.clone(),
                name: p.name.clone(),
                key_span: move_span(p.key_span),
                value: Spanned::new(p.value.node.clone(), move_span(p.value.span)),
            }),
            Err(diags) => Err(diags
                .iter()
                .cloned()
                .map(|mut d| {
                    for l in &mut d.labels {
                        l.span = move_span(l.span);
                    }
                    d
                })
                .collect()),
        }
    }
}

/// An override's parts with spans in the compiler's source map.
pub(crate) struct InFile {
    pub(crate) path: String,
    pub(crate) name: String,
    pub(crate) key_span: Span,
    pub(crate) value: Spanned<Option<SetValue>>,
}

impl std::str::FromStr for Override {
    type Err = std::convert::Infallible;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(Override::parse(s))
    }
}

impl std::fmt::Display for Override {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.arg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_to_their_type() {
        let v = |a: &str| Override::parse(a).value().cloned();
        assert_eq!(v("sigma=0.5"), Some(SetValue::Numbers(vec![0.5])));
        assert_eq!(
            v("t=(1, 2, 3)"),
            Some(SetValue::Numbers(vec![1.0, 2.0, 3.0]))
        );
        assert_eq!(v("b=true"), Some(SetValue::Bool(true)));
        assert_eq!(v("op=aces"), Some(SetValue::Word("aces".into())));
        assert_eq!(v("x=IN[-1]"), None);
        let o = Override::parse("glow/blurX.radius=2");
        assert_eq!(
            (o.path(), o.name(), o.key()),
            ("glow/blurX", "radius", "glow/blurX.radius")
        );
        assert!(!Override::parse("sigma").is_valid());
        assert!(!Override::parse("=1").is_valid());
        assert!(!Override::parse("x=(1,").is_valid());
    }
}
