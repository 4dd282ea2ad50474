//! pest parser: source text → generic statement tree ([`Item`], [`Stmt`], [`RawValue`]).
//!
//! Syntax errors are reported in user terms ("expected `=` after `img`"), and parsing
//! resumes at the next top-level `EFFECT.`/`MATERIAL.`/`INCLUDE` line, so several
//! broken items in one file are all reported.

use super::diag::{Diagnostic, Diagnostics, FileId, Span, Spanned};
use pest::iterators::Pair;
use pest::Parser as _;

#[derive(pest_derive::Parser)]
#[grammar = "script/grammar.pest"]
struct FxParser;

/// Deepest nesting of `{` and `(` accepted (keeps the recursive parser's stack bounded).
pub const MAX_NESTING: usize = 64;

/// A dotted name such as `OUT.SCALE`, `PASS.blurX` or `EFFECT.glow`.
#[derive(Debug, Clone, PartialEq)]
pub struct Key {
    pub parts: Vec<Spanned<String>>,
    pub span: Span,
}

impl Key {
    /// True if the parts equal `names` exactly.
    pub fn is(&self, names: &[&str]) -> bool {
        self.parts.len() == names.len() && self.parts.iter().zip(names).all(|(p, n)| p.node == *n)
    }
    pub fn first(&self) -> &str {
        &self.parts[0].node
    }
    pub fn dotted(&self) -> String {
        self.parts
            .iter()
            .map(|p| p.node.as_str())
            .collect::<Vec<_>>()
            .join(".")
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum RawValue {
    /// `{ stmt* }`
    Block(Vec<Stmt>),
    /// `SHADER.blurX { ... }`, `FLOAT { ... }`
    Ctor {
        kind: Key,
        body: Vec<Stmt>,
    },
    /// `(0.5, 0.5)`
    Tuple(Vec<Spanned<RawValue>>),
    Number(f64),
    Str(String),
    /// `IN`, `PASS.blurX`, `rgba16f`, `IN[-1]`
    Ref {
        key: Key,
        frame: Option<Spanned<i32>>,
    },
}

impl RawValue {
    /// A short description of what kind of value this is, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            RawValue::Block(_) => "a block `{ ... }`",
            RawValue::Ctor { .. } => "a definition `NAME { ... }`",
            RawValue::Tuple(_) => "a tuple",
            RawValue::Number(_) => "a number",
            RawValue::Str(_) => "a string",
            RawValue::Ref { .. } => "a name",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Stmt {
    pub key: Key,
    pub value: Spanned<RawValue>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    Include(Spanned<String>),
    Stmt(Stmt),
}

/// Parse a whole file. Items that parse are returned even when others fail.
pub fn parse(file: FileId, text: &str, diags: &mut Diagnostics) -> Vec<Item> {
    pest::set_error_detail(true);
    if let Some(d) = check_nesting(file, text) {
        diags.push(d);
        return Vec::new();
    }
    let mut items = Vec::new();
    let mut offset = 0usize;
    let mut rule = Rule::file;
    loop {
        let rest = &text[offset..];
        match FxParser::parse(rule, rest) {
            Ok(mut pairs) => {
                collect_items(pairs.next().expect("root"), file, offset, &mut items);
                return items;
            }
            Err(err) => {
                let d = syntax_error(file, text, offset, &err);
                let pos = d.primary_span().map(|s| s.start as usize).unwrap_or(offset);
                diags.push(d);
                // The complete items before the broken one still count.
                if let Ok(mut good) = FxParser::parse(Rule::items, rest) {
                    collect_items(good.next().expect("items"), file, offset, &mut items);
                }
                match next_item_start(text, pos) {
                    Some(next) => {
                        offset = next;
                        rule = Rule::file_tail;
                    }
                    None => return items,
                }
            }
        }
    }
}

/// The next line at or after `pos` that starts (in column 1) with `EFFECT`, `MATERIAL`
/// or `INCLUDE`.
fn next_item_start(text: &str, pos: usize) -> Option<usize> {
    let mut line_start = text[..pos.min(text.len())]
        .rfind('\n')
        .map(|i| i + 1)
        .unwrap_or(0);
    // Skip the line containing pos.
    loop {
        let nl = text[line_start..].find('\n')?;
        line_start += nl + 1;
        let line = &text[line_start..];
        if line.starts_with("EFFECT")
            || line.starts_with("MATERIAL")
            || line.to_ascii_uppercase().starts_with("INCLUDE")
        {
            return Some(line_start);
        }
    }
}

fn check_nesting(file: FileId, text: &str) -> Option<Diagnostic> {
    let mut depth = 0usize;
    for (i, c) in text.char_indices() {
        match c {
            '{' | '(' | '[' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some(
                        Diagnostic::error(format!(
                            "blocks are nested more than {MAX_NESTING} deep"
                        ))
                        .at(Span::new(file, i, i + 1), "too deep"),
                    );
                }
            }
            '}' | ')' | ']' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

fn rule_words(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::stmt | Rule::key | Rule::ident => "a name",
        Rule::value
        | Rule::block
        | Rule::ctor
        | Rule::tuple
        | Rule::reference
        | Rule::number
        | Rule::string => "a value",
        Rule::include => "`INCLUDE`",
        Rule::item => "`EFFECT.name = { ... }` or `INCLUDE \"file.fx\"`",
        Rule::EOI => "end of file",
        Rule::frame => "`[`",
        Rule::offset => "a frame offset such as `-1` or `+1`",
        _ => return None,
    })
}

fn syntax_error(
    file: FileId,
    text: &str,
    base: usize,
    err: &pest::error::Error<Rule>,
) -> Diagnostic {
    let mut pos = base
        + match err.location {
            pest::error::InputLocation::Pos(p) => p,
            pest::error::InputLocation::Span((s, _)) => s,
        };
    let mut expected: Vec<String> = Vec::new();
    if let pest::error::ErrorVariant::ParsingError { positives, .. } = &err.variant {
        expected.extend(
            positives
                .iter()
                .filter_map(|r| rule_words(*r))
                .map(str::to_string),
        );
    }
    // The furthest point the parser reached says more than the rule that failed.
    if let Some(attempts) = err.parse_attempts() {
        if base + attempts.max_position > pos {
            pos = base + attempts.max_position;
            // What could follow there, in rule terms (ParseAttempt is not exported,
            // so the parent rule of each attempt stands for it).
            expected = attempts
                .call_stacks
                .iter()
                .filter_map(|c| c.parent.and_then(rule_words))
                .map(str::to_string)
                .collect();
        }
        for t in attempts.expected_tokens() {
            // ParsingToken is not exported; its Display is the token text.
            let token = t.to_string();
            if ["=", "{", "}", "(", ")", ",", "]", "."].contains(&token.as_str()) {
                expected.push(format!("`{token}`"));
            }
        }
    }
    expected.sort();
    expected.dedup();
    // Punctuation first: it is usually the real mistake.
    expected.sort_by_key(|e| !e.starts_with('`'));
    let found = describe_found(text, pos);
    let what = match expected.len() {
        0 => "unexpected input".to_string(),
        1 => format!("expected {}", expected[0]),
        n => format!(
            "expected {} or {}",
            expected[..n - 1].join(", "),
            expected[n - 1]
        ),
    };
    let end = (pos + found.1).min(text.len());
    Diagnostic::error(format!("syntax error: {what}, found {}", found.0))
        .at(Span::new(file, pos, end), format!("{what} here"))
}

/// A description of the token at `pos` and its length in bytes.
fn describe_found(text: &str, pos: usize) -> (String, usize) {
    let rest = &text[pos.min(text.len())..];
    match rest.chars().next() {
        None => ("end of file".to_string(), 0),
        Some(c) if c.is_alphanumeric() || c == '_' => {
            let len = rest
                .find(|ch: char| !(ch.is_alphanumeric() || ch == '_' || ch == '-'))
                .unwrap_or(rest.len());
            (format!("`{}`", &rest[..len]), len)
        }
        Some('\n') | Some('\r') => ("end of line".to_string(), 0),
        Some(c) => (format!("`{c}`"), c.len_utf8()),
    }
}

fn span_of(pair: &Pair<Rule>, file: FileId, base: usize) -> Span {
    let s = pair.as_span();
    Span::new(file, base + s.start(), base + s.end())
}

fn collect_items(root: Pair<Rule>, file: FileId, base: usize, out: &mut Vec<Item>) {
    for p in root.into_inner() {
        if p.as_rule() != Rule::item {
            continue;
        }
        let inner = p.into_inner().next().expect("item has one child");
        match inner.as_rule() {
            Rule::include => {
                let s = inner.into_inner().next().expect("include string");
                out.push(Item::Include(build_string(s, file, base)));
            }
            Rule::stmt => out.push(Item::Stmt(build_stmt(inner, file, base))),
            r => unreachable!("unexpected rule {r:?}"),
        }
    }
}

fn build_string(p: Pair<Rule>, file: FileId, base: usize) -> Spanned<String> {
    let span = span_of(&p, file, base);
    let raw = p.into_inner().next().map(|i| i.as_str()).unwrap_or("");
    Spanned::new(unescape(raw), span)
}

fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(o) => out.push(o),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}

fn build_key(p: Pair<Rule>, file: FileId, base: usize) -> Key {
    let span = span_of(&p, file, base);
    let parts = p
        .into_inner()
        .map(|i| Spanned::new(i.as_str().to_string(), span_of(&i, file, base)))
        .collect();
    Key { parts, span }
}

fn build_stmt(p: Pair<Rule>, file: FileId, base: usize) -> Stmt {
    let span = span_of(&p, file, base);
    let mut it = p.into_inner();
    let key = build_key(it.next().expect("stmt key"), file, base);
    let value = build_value(it.next().expect("stmt value"), file, base);
    Stmt { key, value, span }
}

fn build_block(p: Pair<Rule>, file: FileId, base: usize) -> Vec<Stmt> {
    p.into_inner().map(|s| build_stmt(s, file, base)).collect()
}

fn build_value(p: Pair<Rule>, file: FileId, base: usize) -> Spanned<RawValue> {
    let inner = if p.as_rule() == Rule::value {
        p.into_inner().next().expect("value has one child")
    } else {
        p
    };
    let span = span_of(&inner, file, base);
    let v = match inner.as_rule() {
        Rule::block => RawValue::Block(build_block(inner, file, base)),
        Rule::ctor => {
            let mut it = inner.into_inner();
            let kind = build_key(it.next().expect("ctor key"), file, base);
            let body = build_block(it.next().expect("ctor block"), file, base);
            RawValue::Ctor { kind, body }
        }
        Rule::tuple => RawValue::Tuple(
            inner
                .into_inner()
                .map(|v| build_value(v, file, base))
                .collect(),
        ),
        Rule::number => RawValue::Number(inner.as_str().parse().unwrap_or(f64::NAN)),
        Rule::string => RawValue::Str(build_string(inner, file, base).node),
        Rule::reference => {
            let mut it = inner.into_inner();
            let key = build_key(it.next().expect("reference key"), file, base);
            let frame = it.next().map(|f| {
                let off = f.into_inner().next().expect("frame offset");
                let fspan = span_of(&off, file, base);
                // Offsets beyond i32 saturate; the checker rejects large ones anyway.
                let n = off
                    .as_str()
                    .trim_start_matches('+')
                    .parse::<i64>()
                    .unwrap_or(i64::MAX)
                    .clamp(-(i32::MAX as i64), i32::MAX as i64) as i32;
                Spanned::new(n, fspan)
            });
            RawValue::Ref { key, frame }
        }
        r => unreachable!("unexpected value rule {r:?}"),
    };
    Spanned::new(v, span)
}

/// Parse `text[offset..]` as a single value (used for `--set NAME=VALUE`).
pub fn parse_value(
    file: FileId,
    text: &str,
    offset: usize,
    diags: &mut Diagnostics,
) -> Option<Spanned<RawValue>> {
    pest::set_error_detail(true);
    if let Some(d) = check_nesting(file, text) {
        diags.push(d);
        return None;
    }
    match FxParser::parse(Rule::value_only, &text[offset..]) {
        Ok(mut pairs) => {
            let root = pairs.next().expect("value_only");
            let v = root.into_inner().next().expect("value");
            Some(build_value(v, file, offset))
        }
        Err(err) => {
            diags.push(syntax_error(file, text, offset, &err));
            None
        }
    }
}
