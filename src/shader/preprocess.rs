//! A small uber-shader preprocessor: `#ifdef`, `#ifndef`, `#if`, `#elif`, `#else`,
//! `#endif`, `#define`. Line numbers are preserved (directive and disabled lines
//! become empty), and every define is appended at the end of the module as an
//! abstract constant `const NAME = value;` (WGSL allows declarations in any order),
//! so columns are preserved too and a define can be used as a loop bound of any
//! integer or float type.

/// A preprocessing error at a 1-based line.
#[derive(Debug, Clone, PartialEq)]
pub struct PreprocessError {
    /// Byte range of the offending directive in the source.
    pub start: usize,
    pub end: usize,
    pub message: String,
}

struct Frame {
    /// This branch is emitted.
    active: bool,
    /// Some branch of this `#if` chain was taken already.
    taken: bool,
    /// The enclosing context is active.
    parent: bool,
    else_seen: bool,
    start: usize,
}

/// The lines of `text` (with their line endings), each with the byte offset
/// where it starts.
pub(crate) fn lines_with_offsets(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split_inclusive('\n').scan(0, |offset, line| {
        let start = *offset;
        *offset += line.len();
        Some((start, line))
    })
}

/// Preprocess `source` with `defines` (from the script; they override `#define`s
/// in the shader, which act as defaults). Returns the WGSL text and the final set
/// of defines, sorted.
pub fn preprocess(
    source: &str,
    defines: &[(String, i64)],
) -> Result<(String, Vec<(String, i64)>), PreprocessError> {
    let mut pp = Preprocessor {
        defs: defines.to_vec(),
        script_defined: defines.iter().map(|(n, _)| n.clone()).collect(),
        stack: Vec::new(),
    };
    let mut out = String::with_capacity(source.len() + 64);
    for (start, line) in lines_with_offsets(source) {
        let err = |msg: String| PreprocessError {
            start,
            end: start + line.trim_end().len(),
            message: msg,
        };
        if let Some(rest) = line.trim().strip_prefix('#') {
            pp.directive(rest, start, &err)?;
            out.push_str(if line.ends_with('\n') { "\n" } else { "" });
        } else if pp.active() {
            out.push_str(line);
        } else {
            out.push_str(if line.ends_with('\n') { "\n" } else { "" });
        }
    }
    if let Some(f) = pp.stack.last() {
        let end = source[f.start..]
            .find('\n')
            .map(|i| f.start + i)
            .unwrap_or(source.len());
        return Err(PreprocessError {
            start: f.start,
            end,
            message: "`#if` without `#endif`".into(),
        });
    }
    let mut defs = pp.defs;
    defs.sort();
    if !out.ends_with('\n') {
        out.push('\n');
    }
    for (name, value) in &defs {
        // Only emit a constant the shader does not declare itself.
        if !declares(source, name) {
            out.push_str(&format!("const {name} = {value};\n"));
        }
    }
    Ok((out, defs))
}

/// The state of [`preprocess`] between lines.
struct Preprocessor {
    /// The defines so far: the script's, then the shader's `#define`s.
    defs: Vec<(String, i64)>,
    /// Names the script defines (a shader `#define` does not change them).
    script_defined: Vec<String>,
    /// The open `#if` chains, innermost last.
    stack: Vec<Frame>,
}

/// Builds the error of the current line from a message.
type LineError<'a> = dyn Fn(String) -> PreprocessError + 'a;

impl Preprocessor {
    /// Whether the current line is emitted.
    fn active(&self) -> bool {
        self.stack.last().map(|f| f.active).unwrap_or(true)
    }

    /// The directive line `#rest` starting at byte `start`.
    fn directive(
        &mut self,
        rest: &str,
        start: usize,
        err: &LineError,
    ) -> Result<(), PreprocessError> {
        let mut words = rest.split_whitespace();
        let directive = words.next().unwrap_or("");
        let args: Vec<&str> = words.collect();
        match directive {
            "ifdef" | "ifndef" | "if" => self.open_if(directive, &args, start, err)?,
            "elif" => {
                let cond = eval(&args, &self.defs).map_err(err)?;
                let Some(f) = self.stack.last_mut() else {
                    return Err(err("`#elif` without `#if`".into()));
                };
                if f.else_seen {
                    return Err(err("`#elif` after `#else`".into()));
                }
                f.active = f.parent && !f.taken && cond;
                f.taken |= cond;
            }
            "else" => {
                let Some(f) = self.stack.last_mut() else {
                    return Err(err("`#else` without `#if`".into()));
                };
                if f.else_seen {
                    return Err(err("a second `#else`".into()));
                }
                f.else_seen = true;
                f.active = f.parent && !f.taken;
                f.taken = true;
            }
            "endif" => {
                if self.stack.pop().is_none() {
                    return Err(err("`#endif` without `#if`".into()));
                }
            }
            "define" if self.active() => self.define(&args, err)?,
            "define" => {}
            other => return Err(err(format!("unknown directive `#{other}`"))),
        }
        Ok(())
    }

    /// `#ifdef NAME`, `#ifndef NAME` or `#if EXPR`: a new chain.
    fn open_if(
        &mut self,
        directive: &str,
        args: &[&str],
        start: usize,
        err: &LineError,
    ) -> Result<(), PreprocessError> {
        let active = self.active();
        let cond = match directive {
            "ifdef" | "ifndef" => {
                let [name] = args else {
                    return Err(err(format!("`#{directive}` takes one name")));
                };
                let defined = self.defs.iter().any(|(d, _)| d == name);
                defined == (directive == "ifdef")
            }
            _ => eval(args, &self.defs).map_err(err)?,
        };
        self.stack.push(Frame {
            active: active && cond,
            taken: cond,
            parent: active,
            else_seen: false,
            start,
        });
        Ok(())
    }

    /// `#define NAME [integer]` in an emitted branch: a default, unless the
    /// script defines the name.
    fn define(&mut self, args: &[&str], err: &LineError) -> Result<(), PreprocessError> {
        let (name, value) = match args {
            [name] => (*name, 1),
            [name, value] => (
                *name,
                value.parse::<i64>().map_err(|_| {
                    err(format!(
                        "`#define {name}` takes an integer value, found `{value}`"
                    ))
                })?,
            ),
            _ => return Err(err("expected `#define NAME [integer]`".into())),
        };
        if !is_ident(name) {
            return Err(err(format!("`{name}` is not a valid name")));
        }
        // Script values win: a shader `#define` is a default.
        if !self.script_defined.iter().any(|d| d == name) {
            self.defs.retain(|(d, _)| d != name);
            self.defs.push((name.to_string(), value));
        }
        Ok(())
    }
}

fn is_ident(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(ch) if ch.is_ascii_alphabetic() || ch == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

fn declares(source: &str, name: &str) -> bool {
    source.lines().any(|l| {
        let t = l.trim_start();
        [
            "const ",
            "override ",
            "var ",
            "let ",
            "fn ",
            "struct ",
            "alias ",
        ]
        .iter()
        .any(|kw| {
            t.strip_prefix(kw).is_some_and(|r| {
                r.trim_start().starts_with(name)
                    && r.trim_start()[name.len()..]
                        .starts_with(|c: char| !c.is_ascii_alphanumeric() && c != '_')
            })
        })
    })
}

/// `#if NAME`, `#if !NAME`, `#if NAME == 3` (also !=, <, <=, >, >=), `#if defined(NAME)`.
fn eval(args: &[&str], defs: &[(String, i64)]) -> Result<bool, String> {
    let joined = args.join(" ");
    let value_of = |t: &str| -> Result<i64, String> {
        let t = t.trim();
        if let Some(inner) = t.strip_prefix("defined(").and_then(|r| r.strip_suffix(')')) {
            return Ok(defs.iter().any(|(d, _)| d == inner.trim()) as i64);
        }
        if let Ok(n) = t.parse::<i64>() {
            return Ok(n);
        }
        if !is_ident(t) {
            return Err(format!("cannot evaluate `{t}` in `#if`"));
        }
        Ok(defs
            .iter()
            .find(|(d, _)| d == t)
            .map(|(_, v)| *v)
            .unwrap_or(0))
    };
    if joined.trim().is_empty() {
        return Err("`#if` needs a condition".into());
    }
    for op in ["==", "!=", "<=", ">=", "<", ">"] {
        if let Some((a, b)) = joined.split_once(op) {
            let (a, b) = (value_of(a)?, value_of(b)?);
            return Ok(match op {
                "==" => a == b,
                "!=" => a != b,
                "<=" => a <= b,
                ">=" => a >= b,
                "<" => a < b,
                _ => a > b,
            });
        }
    }
    match joined.trim().strip_prefix('!') {
        Some(rest) => Ok(value_of(rest)? == 0),
        None => Ok(value_of(&joined)? != 0),
    }
}
