//! Feature flags of material surface shaders (`#ifdef HAS_BASE_COLOR_MAP`, ...) and
//! the three ways of compiling them.
//!
//! - [`FeatureMode::Preprocess`]: the flags are defines of the ordinary
//!   preprocessor ([`crate::shader::preprocess`]); one shader per combination.
//! - [`FeatureMode::Override`]: every feature directive becomes an `if` on a
//!   pipeline-overridable constant (`override HAS_X: bool = false;` is appended);
//!   one shader module, one pipeline per combination.
//! - [`FeatureMode::Branch`]: the same `if`s on a caller-supplied run-time
//!   expression per flag (e.g. `(fx_features.x & 4u) != 0u`); one pipeline.
//!
//! The conversion replaces each directive line in place (`#ifdef X` → `if X {`,
//! `#ifndef X` → `if !X {`, `#else` → `} else {`, `#endif` → `}`), so every line
//! keeps its number. Feature blocks must therefore lie inside function bodies,
//! contain whole statements, and not declare names used after the block.
//! Directives on other names are left for the preprocessor.

use super::preprocess::{lines_with_offsets, PreprocessError};

/// How a surface shader's feature flags are compiled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FeatureMode {
    Preprocess,
    Override,
    Branch,
}

/// Flags the engine sets from the mesh and the material, in every surface shader.
pub const ENGINE_FLAGS: &[&str] = &[
    "ALPHA_MASK",
    "ALPHA_BLEND",
    "DOUBLE_SIDED",
    "HAS_UV1",
    "HAS_VERTEX_COLOR",
    "HAS_TANGENTS",
    // the material turns on a layer: a `clearcoat` or `transmission` setting > 0
    "HAS_LAYERS",
];

/// The flag set when a texture is bound: `base_color_map` → `HAS_BASE_COLOR_MAP`.
pub fn texture_flag(texture: &str) -> String {
    format!("HAS_{}", texture.to_ascii_uppercase())
}

/// The names tested by `#ifdef`/`#ifndef` lines that look like feature flags (an
/// engine flag or `HAS_...`), sorted, each once.
pub fn feature_flags_used(text: &str) -> Vec<String> {
    let mut out: Vec<String> = text
        .lines()
        .filter_map(|l| {
            let t = l.trim();
            let rest = t
                .strip_prefix("#ifdef")
                .or_else(|| t.strip_prefix("#ifndef"))?;
            let mut words = rest.split_whitespace();
            let name = words.next()?;
            (words.next().is_none()
                && rest.starts_with(char::is_whitespace)
                && (ENGINE_FLAGS.contains(&name) || name.starts_with("HAS_")))
            .then(|| name.to_string())
        })
        .collect();
    out.sort();
    out.dedup();
    out
}

/// The `override NAME: bool = false;` declarations of [`FeatureMode::Override`].
pub fn override_declarations(flags: &[&str]) -> String {
    flags
        .iter()
        .map(|f| format!("override {f}: bool = false;\n"))
        .collect()
}

/// What an open `#if...` is, for the conversion.
#[derive(Clone, Copy, PartialEq)]
enum Open {
    /// A feature directive turned into `if`.
    Feature,
    /// Anything else: left for the preprocessor.
    Other,
}

/// Turn the feature directives of `text` into `if` statements: `cond(flag)` is the
/// WGSL boolean expression of a flag (the flag's name for override constants).
/// Only directives on names in `flags` are converted; line numbers are kept.
pub fn convert_features(
    text: &str,
    flags: &[&str],
    cond: impl Fn(&str) -> String,
) -> Result<String, PreprocessError> {
    let mut out = String::with_capacity(text.len() + 64);
    let mut conv = Converter {
        flags,
        cond: &cond,
        stack: Vec::new(),
        depth: BraceDepth::default(),
    };
    for (start, line) in lines_with_offsets(text) {
        let body = line.trim_end_matches(['\n', '\r']);
        let eol = &line[body.len()..];
        let t = body.trim_start();
        let indent = &body[..body.len() - t.len()];
        let err = |msg: String| PreprocessError {
            start: start + indent.len(),
            end: start + body.len(),
            message: msg,
        };
        let Some(rest) = t.strip_prefix('#') else {
            conv.depth.scan(body);
            out.push_str(line);
            continue;
        };
        match conv.directive(rest, &err)? {
            Some(code) => {
                out.push_str(indent);
                out.push_str(&code);
                out.push_str(eol);
            }
            None => out.push_str(line),
        }
    }
    Ok(out)
}

/// The state of [`convert_features`] between lines.
struct Converter<'a> {
    flags: &'a [&'a str],
    cond: &'a dyn Fn(&str) -> String,
    /// The open `#if` blocks, innermost last.
    stack: Vec<Open>,
    depth: BraceDepth,
}

impl Converter<'_> {
    /// The directive line `#rest`: the code it becomes, or `None` to keep it
    /// for the preprocessor.
    fn directive(
        &mut self,
        rest: &str,
        err: &dyn Fn(String) -> PreprocessError,
    ) -> Result<Option<String>, PreprocessError> {
        let mut words = rest.split_whitespace();
        let directive = words.next().unwrap_or("");
        let args: Vec<&str> = words.collect();
        let flags = self.flags;
        Ok(match directive {
            "ifdef" | "ifndef" => match args.as_slice() {
                [name] if flags.contains(name) => {
                    if self.depth.depth == 0 {
                        return Err(err(format!(
                            "feature flag `{name}` used outside a function: feature blocks must be statements inside a function body"
                        )));
                    }
                    self.stack.push(Open::Feature);
                    let c = (self.cond)(name);
                    Some(if directive == "ifdef" {
                        format!("if {c} {{")
                    } else {
                        format!("if !({c}) {{")
                    })
                }
                _ => {
                    self.stack.push(Open::Other);
                    None
                }
            },
            "if" => {
                if let Some(f) = args.iter().find_map(|a| tested_flag(a, flags)) {
                    return Err(err(format!(
                        "test feature flag `{f}` with `#ifdef {f}` or `#ifndef {f}`, not `#if`"
                    )));
                }
                self.stack.push(Open::Other);
                None
            }
            "elif" => {
                if self.stack.last() == Some(&Open::Feature) {
                    return Err(err(
                        "`#elif` after a feature `#ifdef`: nest `#ifdef`s in the `#else` instead"
                            .into(),
                    ));
                }
                None
            }
            "else" => (self.stack.last() == Some(&Open::Feature)).then(|| "} else {".to_string()),
            "endif" => match self.stack.pop() {
                Some(Open::Feature) => Some("}".to_string()),
                _ => None,
            },
            "define" | "undef" if args.first().is_some_and(|a| flags.contains(a)) => {
                return Err(err(format!(
                    "`{}` is a feature flag set by the engine; it cannot be `#{directive}`d",
                    args[0]
                )));
            }
            _ => None,
        })
    }
}

/// The feature flag an `#if` argument tests (`FLAG`, `!FLAG`, `defined(FLAG)`).
fn tested_flag<'f>(arg: &str, flags: &[&'f str]) -> Option<&'f str> {
    let a = arg.trim_start_matches('!');
    let a = a
        .strip_prefix("defined(")
        .and_then(|r| r.strip_suffix(')'))
        .unwrap_or(a);
    flags.iter().find(|f| **f == a).copied()
}

/// [`convert_features`] for [`FeatureMode::Override`], with the `override`
/// declarations of every flag in `flags` appended (so a pipeline may set any of them).
pub fn to_override_mode(text: &str, flags: &[&str]) -> Result<String, PreprocessError> {
    let mut out = convert_features(text, flags, |f| f.to_string())?;
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&override_declarations(flags));
    Ok(out)
}

/// Tracks `{`/`}` nesting outside comments, line by line.
#[derive(Default)]
struct BraceDepth {
    depth: i64,
    in_block_comment: usize,
}

impl BraceDepth {
    fn scan(&mut self, line: &str) {
        let b = line.as_bytes();
        let mut i = 0;
        while i < b.len() {
            if self.in_block_comment > 0 {
                if b[i..].starts_with(b"*/") {
                    self.in_block_comment -= 1;
                    i += 2;
                } else if b[i..].starts_with(b"/*") {
                    self.in_block_comment += 1;
                    i += 2;
                } else {
                    i += 1;
                }
                continue;
            }
            if b[i..].starts_with(b"//") {
                return;
            }
            if b[i..].starts_with(b"/*") {
                self.in_block_comment += 1;
                i += 2;
                continue;
            }
            match b[i] {
                b'{' => self.depth += 1,
                b'}' => self.depth -= 1,
                _ => {}
            }
            i += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "fn f() -> f32 {\n    var x = 0.0;\n    #ifdef HAS_A\n    x = 1.0;\n    #else\n  #ifndef B\n    x = 2.0;\n  #endif\n    #endif\n#ifndef HAS_A\n    x += 1.0;\n#endif\n    return x;\n}\n";

    #[test]
    fn conversion_keeps_lines() {
        let out = convert_features(SRC, &["HAS_A"], |f| format!("({f} != 0u)")).unwrap();
        assert_eq!(out.lines().count(), SRC.lines().count());
        assert_eq!(
            out,
            "fn f() -> f32 {\n    var x = 0.0;\n    if (HAS_A != 0u) {\n    x = 1.0;\n    } else {\n  #ifndef B\n    x = 2.0;\n  #endif\n    }\nif !((HAS_A != 0u)) {\n    x += 1.0;\n}\n    return x;\n}\n"
        );
        let o = to_override_mode(SRC, &["HAS_A", "HAS_Z"]).unwrap();
        assert!(o.contains("    if HAS_A {\n"));
        assert!(o.ends_with("}\noverride HAS_A: bool = false;\noverride HAS_Z: bool = false;\n"));
        // The result still goes through the preprocessor for `B`.
        let (p, _) = crate::shader::preprocess(&o, &[]).unwrap();
        naga::front::wgsl::parse_str(&p).unwrap();
    }

    #[test]
    fn errors() {
        let e = convert_features("#ifdef HAS_A\nfn f() {}\n#endif\n", &["HAS_A"], |f| {
            f.into()
        })
        .unwrap_err();
        assert!(e.message.contains("outside a function"), "{}", e.message);
        assert_eq!((e.start, e.end), (0, 12));
        let e = convert_features("fn f() {\n#if HAS_A\n#endif\n}\n", &["HAS_A"], |f| f.into())
            .unwrap_err();
        assert!(e.message.contains("with `#ifdef HAS_A`"), "{}", e.message);
        let e = convert_features(
            "fn f() {\n#ifdef HAS_A\n#elif B\n#endif\n}\n",
            &["HAS_A"],
            |f| f.into(),
        )
        .unwrap_err();
        assert!(e.message.contains("`#elif`"), "{}", e.message);
    }

    #[test]
    fn flags_used() {
        assert_eq!(
            feature_flags_used(SRC),
            vec!["HAS_A".to_string()] // `B` is not a feature flag
        );
        assert_eq!(
            feature_flags_used("#ifdef DOUBLE_SIDED\n#ifndef HAS_UV1\n#ifdef OTHER\n"),
            vec!["DOUBLE_SIDED".to_string(), "HAS_UV1".to_string()]
        );
        assert_eq!(texture_flag("base_color_map"), "HAS_BASE_COLOR_MAP");
    }
}
