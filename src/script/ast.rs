//! Typed AST of the EFFECT language, built from the generic tree by a checker that
//! collects every mistake (unknown attribute, wrong value type, duplicate name, ...)
//! with its span. Cross-effect checks (unknown effect, cycles, sizes) are done when
//! lowering to the graph.

use super::diag::{Diagnostic, Diagnostics, FileId, Span, Spanned};
use super::material::{self, MaterialDef};
use super::parse::{Item, Key, RawValue, Stmt};
use super::types::*;

/// One parsed and checked `.fx` file.
#[derive(Debug, Clone, Default)]
pub struct Module {
    pub file: FileId,
    pub includes: Vec<Spanned<String>>,
    pub effects: Vec<EffectDef>,
    /// `MATERIAL.name = { ... }` definitions, in file order (see [`material`]).
    pub materials: Vec<MaterialDef>,
}

#[derive(Debug, Clone)]
pub struct EffectDef {
    pub name: Spanned<String>,
    pub description: Option<String>,
    pub params: Vec<ParamDecl>,
    pub passes: Vec<PassDef>,
    pub out: Option<OutRef>,
    /// Default output format for this effect's passes.
    pub format: Option<Spanned<FormatSpec>>,
    /// Default working colour space for this effect's passes.
    pub colorspace: Option<Spanned<ColorSpace>>,
    pub span: Span,
}

impl EffectDef {
    pub fn pass(&self, name: &str) -> Option<&PassDef> {
        self.passes.iter().find(|p| p.name.node == name)
    }
    pub fn param(&self, name: &str) -> Option<&ParamDecl> {
        self.params.iter().find(|p| p.name.node == name)
    }
}

/// `OUT = final`, `OUT = PASS.final` or `OUT = IN`.
#[derive(Debug, Clone, PartialEq)]
pub enum OutRef {
    In(Span),
    Pass(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct ParamDecl {
    pub name: Spanned<String>,
    pub ty: ParamType,
    pub default: Value,
    pub range: Option<(f64, f64)>,
    pub description: String,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum PassKind {
    /// `SHADER.name`: a WGSL fragment shader.
    Shader(Spanned<String>),
    /// `EFFECT.name`: another effect instantiated as a node.
    Effect(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct PassDef {
    pub name: Spanned<String>,
    pub kind: PassKind,
    pub inputs: Vec<InputDef>,
    pub params: Vec<ParamSet>,
    pub defines: Vec<DefineSet>,
    pub out: OutSpec,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct InputDef {
    pub name: Spanned<String>,
    pub source: Spanned<Source>,
    pub filter: Option<Spanned<Filter>>,
    pub wrap: Option<Spanned<(Wrap, Wrap)>>,
    /// The colour space the shader expects this input in (default: the pass's).
    pub colorspace: Option<Spanned<ColorSpace>>,
}

impl InputDef {
    pub fn sampling(&self) -> Sampling {
        let (wrap_u, wrap_v) = self.wrap.as_ref().map(|w| w.node).unwrap_or_default();
        Sampling {
            filter: self.filter.as_ref().map(|f| f.node).unwrap_or_default(),
            wrap_u,
            wrap_v,
        }
    }
}

/// Where an input comes from. `frame` is 0 for the current frame, negative for
/// earlier frames, positive for later frames (input only).
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    In { frame: i32 },
    Pass { name: Spanned<String>, frame: i32 },
    Aux { name: Spanned<String> },
}

#[derive(Debug, Clone)]
pub struct ParamSet {
    pub name: Spanned<String>,
    pub value: Spanned<ParamArg>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ParamArg {
    /// Numbers (a bool is written `true`/`false` and stored as 1/0).
    Literal { value: Value, is_bool: bool },
    /// A bare word: an enum choice of the receiving parameter.
    Word(String),
    /// `PARAM.name`: the enclosing effect's parameter.
    Param(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct DefineSet {
    pub name: Spanned<String>,
    pub value: Spanned<DefineArg>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum DefineArg {
    Int(i64),
    Param(Spanned<String>),
}

#[derive(Debug, Clone, Default)]
pub struct OutSpec {
    pub size: Option<Spanned<(u32, u32)>>,
    pub scale: Option<Spanned<(f64, f64)>>,
    pub relative_to: Option<Spanned<String>>,
    pub format: Option<Spanned<FormatSpec>>,
    pub colorspace: Option<Spanned<ColorSpace>>,
}

/// `OUT.FORMAT = rgba16f` or `OUT.FORMAT = IN` (the effect input's format).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FormatSpec {
    Fixed(Format),
    SameAsInput,
}

/// Largest absolute frame offset accepted in `IN[n]` / `PASS.x[-n]`.
pub const MAX_FRAME_OFFSET: i32 = 16;
/// Largest texture side accepted.
pub const MAX_SIDE: u32 = 16384;

const FORMAT_LIST: &str =
    "rgba8, rgba8-srgb, rgba16f, rgba32f, rgb10a2, r8, r16f, r32f, rg16f, rg32f";

/// Check a parsed file and build its typed AST.
pub fn check(file: FileId, items: &[Item], diags: &mut Diagnostics) -> Module {
    let mut module = Module {
        file,
        ..Default::default()
    };
    // Names of every `MATERIAL.name` seen, including ones whose body had errors.
    let mut material_names: Vec<Spanned<String>> = Vec::new();
    for item in items {
        match item {
            Item::Include(path) => module.includes.push(path.clone()),
            Item::Stmt(stmt) => {
                if stmt.key.first() == "MATERIAL" {
                    if let Some(m) = material::check_top_level(stmt, &mut material_names, diags) {
                        module.materials.push(m);
                    }
                } else if stmt.key.first() == "EFFECT" && stmt.key.parts.len() == 2 {
                    let name = stmt.key.parts[1].clone();
                    if let Some(prev) = module.effects.iter().find(|e| e.name.node == name.node) {
                        diags.push(
                            Diagnostic::error(format!("effect `{}` is defined twice", name.node))
                                .at(name.span, "defined again here")
                                .also(prev.name.span, "first defined here"),
                        );
                        continue;
                    }
                    match &stmt.value.node {
                        RawValue::Block(body) => module
                            .effects
                            .push(check_effect(name, body, stmt.span, diags)),
                        other => diags.push(
                            Diagnostic::error(format!(
                                "an effect is defined with a block, found {}",
                                other.kind_name()
                            ))
                            .at(stmt.value.span, "expected `{ PASS = { ... } OUT = ... }`"),
                        ),
                    }
                } else {
                    let mut d = Diagnostic::error(format!(
                        "unknown top-level statement `{}`",
                        stmt.key.dotted()
                    ))
                    .at(
                        stmt.key.span,
                        "expected `EFFECT.name = { ... }` or `INCLUDE \"file.fx\"`",
                    );
                    // `MATERAIL.brick = ...`: a misspelt definition keyword.
                    if stmt.key.parts.len() == 2 {
                        if let Some(s) =
                            suggest(stmt.key.first(), ["EFFECT", "MATERIAL"].into_iter())
                        {
                            d = d.note(format!("did you mean `{s}.{}`?", stmt.key.parts[1].node));
                        }
                    }
                    diags.push(d);
                }
            }
        }
    }
    module
}

fn check_effect(
    name: Spanned<String>,
    body: &[Stmt],
    span: Span,
    diags: &mut Diagnostics,
) -> EffectDef {
    let mut e = EffectDef {
        name,
        description: None,
        params: Vec::new(),
        passes: Vec::new(),
        out: None,
        format: None,
        colorspace: None,
        span,
    };
    let mut seen: Vec<(String, Span)> = Vec::new();
    // `OUT = ...` was written (even if wrongly): no "missing OUT" error then.
    let mut out_written = false;
    for stmt in body {
        let k = stmt.key.dotted();
        out_written |= k == "OUT";
        if let Some((_, prev)) = seen.iter().find(|(n, _)| *n == k) {
            diags.push(
                Diagnostic::error(format!("`{k}` is set twice in effect `{}`", e.name.node))
                    .at(stmt.key.span, "set again here")
                    .also(*prev, "first set here"),
            );
            continue;
        }
        seen.push((k.clone(), stmt.key.span));
        match k.as_str() {
            "PASS" => match &stmt.value.node {
                RawValue::Block(passes) => {
                    for p in passes {
                        if let Some(pass) = check_pass(p, diags) {
                            if let Some(prev) = e.passes.iter().find(|q| q.name.node == pass.name.node) {
                                diags.push(
                                    Diagnostic::error(format!("pass `{}` is defined twice", pass.name.node))
                                        .at(pass.name.span, "defined again here")
                                        .also(prev.name.span, "first defined here"),
                                );
                            } else {
                                e.passes.push(pass);
                            }
                        }
                    }
                }
                other => diags.push(type_error(stmt, "a block of passes `{ name = SHADER.x { ... } }`", other)),
            },
            "PARAM" => match &stmt.value.node {
                RawValue::Block(params) => {
                    for p in params {
                        if let Some(decl) = check_param_decl(p, diags) {
                            if let Some(prev) = e.params.iter().find(|q| q.name.node == decl.name.node) {
                                diags.push(
                                    Diagnostic::error(format!("parameter `{}` is declared twice", decl.name.node))
                                        .at(decl.name.span, "declared again here")
                                        .also(prev.name.span, "first declared here"),
                                );
                            } else {
                                e.params.push(decl);
                            }
                        }
                    }
                }
                other => diags.push(type_error(stmt, "a block of parameter declarations", other)),
            },
            "OUT" => match &stmt.value.node {
                RawValue::Ref { key, frame } => {
                    if let Some(f) = frame {
                        diags.push(
                            Diagnostic::error("the effect output cannot be an earlier or later frame")
                                .at(f.span, "remove the frame offset"),
                        );
                    } else if key.is(&["IN"]) {
                        e.out = Some(OutRef::In(key.span));
                    } else if key.parts.len() == 1 {
                        e.out = Some(OutRef::Pass(key.parts[0].clone()));
                    } else if key.parts.len() == 2 && key.first() == "PASS" {
                        e.out = Some(OutRef::Pass(key.parts[1].clone()));
                    } else {
                        diags.push(
                            Diagnostic::error(format!("`OUT` must name a pass, found `{}`", key.dotted()))
                                .at(key.span, "expected a pass name such as `final` or `PASS.final`"),
                        );
                    }
                }
                other => diags.push(type_error(stmt, "a pass name", other)),
            },
            "DESCRIPTION" => match &stmt.value.node {
                RawValue::Str(s) => e.description = Some(s.clone()),
                other => diags.push(type_error(stmt, "a string", other)),
            },
            "FORMAT" => e.format = format_spec(stmt, diags),
            "COLORSPACE" => e.colorspace = colorspace_value(stmt, diags),
            _ => diags.push(
                Diagnostic::error(format!("unknown effect attribute `{k}`"))
                    .at(stmt.key.span, "not an effect attribute")
                    .note("an effect may contain PASS, OUT, PARAM, DESCRIPTION, FORMAT and COLORSPACE"),
            ),
        }
    }
    // Every PASS/PARAM reference inside the effect must resolve.
    check_references(&e, diags);
    if e.out.is_none() && !out_written {
        diags.push(
            Diagnostic::error(format!("effect `{}` has no `OUT`", e.name.node))
                .at(
                    e.name.span,
                    "this effect never says which pass is its result",
                )
                .note("add `OUT = <pass name>` after the PASS block"),
        );
    }
    e
}

fn check_references(e: &EffectDef, diags: &mut Diagnostics) {
    let pass_names: Vec<&str> = e.passes.iter().map(|p| p.name.node.as_str()).collect();
    let unknown_pass = |name: &Spanned<String>, diags: &mut Diagnostics| {
        let mut d = Diagnostic::error(format!("unknown pass `{}`", name.node)).at(
            name.span,
            format!("no pass named `{}` in effect `{}`", name.node, e.name.node),
        );
        if let Some(s) = suggest(&name.node, pass_names.iter().copied()) {
            d = d.note(format!("did you mean `{s}`?"));
        } else if !pass_names.is_empty() {
            d = d.note(format!("passes in this effect: {}", pass_names.join(", ")));
        }
        diags.push(d);
    };
    for p in &e.passes {
        for i in &p.inputs {
            if let Source::Pass { name, .. } = &i.source.node {
                if e.pass(&name.node).is_none() {
                    unknown_pass(name, diags);
                }
            }
        }
        let param_refs = p
            .params
            .iter()
            .filter_map(|s| match &s.value.node {
                ParamArg::Param(n) => Some(n),
                _ => None,
            })
            .chain(p.defines.iter().filter_map(|d| match &d.value.node {
                DefineArg::Param(n) => Some(n),
                _ => None,
            }));
        for n in param_refs {
            if e.param(&n.node).is_none() {
                let mut d = Diagnostic::error(format!("unknown effect parameter `{}`", n.node)).at(
                    n.span,
                    format!("effect `{}` declares no such parameter", e.name.node),
                );
                if let Some(s) = suggest(&n.node, e.params.iter().map(|q| q.name.node.as_str())) {
                    d = d.note(format!("did you mean `{s}`?"));
                } else {
                    d = d.note("declare it in a `PARAM = { ... }` block of the effect");
                }
                diags.push(d);
            }
        }
        if let Some(rel) = &p.out.relative_to {
            if !p.inputs.iter().any(|i| i.name.node == rel.node) {
                diags.push(
                    Diagnostic::error(format!(
                        "`OUT.RELATIVE_TO` names `{}`, which is not an input of pass `{}`",
                        rel.node, p.name.node
                    ))
                    .at(rel.span, "not an input of this pass"),
                );
            }
        }
    }
    if let Some(OutRef::Pass(name)) = &e.out {
        if e.pass(&name.node).is_none() {
            unknown_pass(name, diags);
        }
    }
}

/// The closest name within edit distance 2, for "did you mean" notes.
pub fn suggest<'a>(wanted: &str, names: impl Iterator<Item = &'a str>) -> Option<String> {
    names
        .map(|n| (edit_distance(wanted, n), n))
        .filter(|(d, n)| *d <= 2.max(wanted.len() / 4) && *d < n.len().max(wanted.len()))
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n.to_string())
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

pub(super) fn type_error(stmt: &Stmt, expected: &str, found: &RawValue) -> Diagnostic {
    Diagnostic::error(format!(
        "`{}` expects {expected}, found {}",
        stmt.key.dotted(),
        found.kind_name()
    ))
    .at(stmt.value.span, format!("expected {expected}"))
}

pub(super) fn word(v: &Spanned<RawValue>) -> Option<&str> {
    match &v.node {
        RawValue::Ref { key, frame: None } if key.parts.len() == 1 => Some(key.first()),
        _ => None,
    }
}

fn format_spec(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<FormatSpec>> {
    match word(&stmt.value) {
        Some("IN") => Some(Spanned::new(FormatSpec::SameAsInput, stmt.value.span)),
        Some(w) => match Format::from_name(w) {
            Some(f) => Some(Spanned::new(FormatSpec::Fixed(f), stmt.value.span)),
            None => {
                let mut d = Diagnostic::error(format!("unknown pixel format `{w}`"))
                    .at(stmt.value.span, "not a pixel format");
                d = match suggest(w, Format::ALL.iter().map(|f| f.name())) {
                    Some(s) => d.note(format!("did you mean `{s}`? formats: {FORMAT_LIST}, or IN")),
                    None => d.note(format!(
                        "formats: {FORMAT_LIST}, or IN (the effect input's format)"
                    )),
                };
                diags.push(d);
                None
            }
        },
        None => {
            diags.push(type_error(stmt, "a pixel format name", &stmt.value.node));
            None
        }
    }
}

fn colorspace_value(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<ColorSpace>> {
    match word(&stmt.value) {
        Some(w) => match ColorSpace::from_name(w) {
            Some(c) => Some(Spanned::new(c, stmt.value.span)),
            None => {
                diags.push(
                    Diagnostic::error(format!("unknown colour space `{w}`"))
                        .at(stmt.value.span, "expected `linear` or `srgb`"),
                );
                None
            }
        },
        None => {
            diags.push(type_error(stmt, "`linear` or `srgb`", &stmt.value.node));
            None
        }
    }
}

/// Numbers of a number or tuple of numbers.
fn numbers(v: &Spanned<RawValue>) -> Option<Vec<f64>> {
    match &v.node {
        RawValue::Number(n) => Some(vec![*n]),
        RawValue::Tuple(items) => items
            .iter()
            .map(|i| match i.node {
                RawValue::Number(n) => Some(n),
                _ => None,
            })
            .collect(),
        _ => None,
    }
}

fn pair(stmt: &Stmt, diags: &mut Diagnostics, what: &str) -> Option<(f64, f64)> {
    match numbers(&stmt.value) {
        Some(v) if v.len() == 2 => Some((v[0], v[1])),
        Some(v) if v.len() == 1 && stmt.key.dotted() == "OUT.SCALE" => Some((v[0], v[0])),
        _ => {
            diags.push(type_error(stmt, what, &stmt.value.node));
            None
        }
    }
}

fn check_pass(stmt: &Stmt, diags: &mut Diagnostics) -> Option<PassDef> {
    if stmt.key.parts.len() != 1 {
        diags.push(
            Diagnostic::error(format!(
                "a pass name is a single word, found `{}`",
                stmt.key.dotted()
            ))
            .at(stmt.key.span, "expected `name = SHADER.shader { ... }`"),
        );
        return None;
    }
    let name = stmt.key.parts[0].clone();
    if ["IN", "OUT", "PASS", "AUX", "PARAM"].contains(&name.node.as_str()) {
        diags.push(
            Diagnostic::error(format!(
                "`{}` is a reserved word and cannot name a pass",
                name.node
            ))
            .at(name.span, "reserved"),
        );
        return None;
    }
    let (kind, body) = match &stmt.value.node {
        RawValue::Ctor { kind, body } if kind.parts.len() == 2 && kind.first() == "SHADER" => {
            (PassKind::Shader(kind.parts[1].clone()), body)
        }
        RawValue::Ctor { kind, body } if kind.parts.len() == 2 && kind.first() == "EFFECT" => {
            (PassKind::Effect(kind.parts[1].clone()), body)
        }
        RawValue::Ctor { kind, .. } => {
            diags.push(
                Diagnostic::error(format!(
                    "a pass is `SHADER.name {{ ... }}` or `EFFECT.name {{ ... }}`, found `{}`",
                    kind.dotted()
                ))
                .at(kind.span, "expected SHADER.<name> or EFFECT.<name>"),
            );
            return None;
        }
        other => {
            diags.push(
                Diagnostic::error(format!(
                    "pass `{}` must be `SHADER.name {{ ... }}` or `EFFECT.name {{ ... }}`, found {}",
                    name.node,
                    other.kind_name()
                ))
                .at(stmt.value.span, "expected a shader or effect instance"),
            );
            return None;
        }
    };
    let is_effect = matches!(kind, PassKind::Effect(_));
    let mut pass = PassDef {
        name,
        kind,
        inputs: Vec::new(),
        params: Vec::new(),
        defines: Vec::new(),
        out: OutSpec::default(),
        span: stmt.span,
    };
    let mut seen: Vec<(String, Span)> = Vec::new();
    // Sampling attributes refer to inputs that may be bound later in the block.
    let mut sampling: Vec<&Stmt> = Vec::new();
    for s in body {
        let k = s.key.dotted();
        if let Some((_, prev)) = seen.iter().find(|(n, _)| *n == k) {
            diags.push(
                Diagnostic::error(format!("`{k}` is set twice in pass `{}`", pass.name.node))
                    .at(s.key.span, "set again here")
                    .also(*prev, "first set here"),
            );
            continue;
        }
        seen.push((k.clone(), s.key.span));
        let parts: Vec<&str> = s.key.parts.iter().map(|p| p.node.as_str()).collect();
        match parts.as_slice() {
            ["OUT", attr] if !is_effect => check_out_attr(&mut pass.out, attr, s, diags),
            ["OUT", _] => diags.push(
                Diagnostic::error("an effect instance takes its output size and format from the effect itself")
                    .at(s.key.span, "`OUT.*` is not allowed on `EFFECT.` passes"),
            ),
            ["DEFINE", def] if !is_effect => {
                let value = match &s.value.node {
                    RawValue::Number(n) if n.fract() == 0.0 && n.abs() < 1e15 => Some(DefineArg::Int(*n as i64)),
                    RawValue::Ref { key, frame: None } if key.is(&["true"]) => Some(DefineArg::Int(1)),
                    RawValue::Ref { key, frame: None } if key.is(&["false"]) => Some(DefineArg::Int(0)),
                    RawValue::Ref { key, frame: None } if key.parts.len() == 2 && key.first() == "PARAM" => {
                        Some(DefineArg::Param(key.parts[1].clone()))
                    }
                    _ => None,
                };
                match value {
                    Some(v) => pass.defines.push(DefineSet {
                        name: s.key.parts[1].clone(),
                        value: Spanned::new(v, s.value.span),
                    }),
                    None => diags.push(type_error(s, "an integer, `true`, `false` or `PARAM.name`", &s.value.node)),
                }
                let _ = def;
            }
            [_input, "FILTER" | "WRAP" | "COLORSPACE"] => sampling.push(s),
            [single] => {
                let name = s.key.parts[0].clone();
                if *single == "IN" && !is_effect {
                    diags.push(
                        Diagnostic::error("`IN` names the effect input; a shader input needs its own name")
                            .at(s.key.span, "write e.g. `img = IN`"),
                    );
                    continue;
                }
                match classify_binding(s, diags) {
                    Some(Binding::Input(source)) => pass.inputs.push(InputDef {
                        name,
                        source,
                        filter: None,
                        wrap: None,
                        colorspace: None,
                    }),
                    Some(Binding::Param(value)) => pass.params.push(ParamSet { name, value }),
                    None => {}
                }
            }
            _ => diags.push(
                Diagnostic::error(format!("unknown pass attribute `{k}`"))
                    .at(s.key.span, "not a pass attribute")
                    .note("a pass contains inputs (`img = IN`), parameters (`threshold = 0.8`), `img.FILTER`, `img.WRAP`, `img.COLORSPACE`, `OUT.SIZE`, `OUT.SCALE`, `OUT.RELATIVE_TO`, `OUT.FORMAT`, `OUT.COLORSPACE` and `DEFINE.NAME`"),
            ),
        }
    }
    for s in sampling {
        let input_name = &s.key.parts[0];
        let attr = s.key.parts[1].node.as_str();
        let Some(input) = pass
            .inputs
            .iter_mut()
            .find(|i| i.name.node == input_name.node)
        else {
            diags.push(
                Diagnostic::error(format!(
                    "`{}` is not an input of pass `{}`",
                    input_name.node, pass.name.node
                ))
                .at(input_name.span, "bind it first, e.g. `img = IN`"),
            );
            continue;
        };
        match attr {
            "FILTER" => match word(&s.value).and_then(Filter::from_name) {
                Some(f) => input.filter = Some(Spanned::new(f, s.value.span)),
                None => diags.push(
                    Diagnostic::error("unknown filter")
                        .at(s.value.span, "expected `linear` or `nearest`"),
                ),
            },
            "WRAP" => {
                let w = match &s.value.node {
                    RawValue::Tuple(items) if items.len() == 2 => {
                        match (
                            word(&items[0]).and_then(Wrap::from_name),
                            word(&items[1]).and_then(Wrap::from_name),
                        ) {
                            (Some(u), Some(v)) => Some((u, v)),
                            _ => None,
                        }
                    }
                    _ => word(&s.value).and_then(Wrap::from_name).map(|w| (w, w)),
                };
                match w {
                    Some(w) => input.wrap = Some(Spanned::new(w, s.value.span)),
                    None => diags.push(Diagnostic::error("unknown wrap mode").at(
                        s.value.span,
                        "expected `clamp`, `repeat`, `mirror` or a pair `(u, v)` of them",
                    )),
                }
            }
            _ => input.colorspace = colorspace_value(s, diags),
        }
    }
    Some(pass)
}

enum Binding {
    Input(Spanned<Source>),
    Param(Spanned<ParamArg>),
}

fn classify_binding(s: &Stmt, diags: &mut Diagnostics) -> Option<Binding> {
    let span = s.value.span;
    match &s.value.node {
        RawValue::Ref { key, frame } => {
            let frame_n = frame.as_ref().map(|f| f.node).unwrap_or(0);
            if let Some(f) = frame {
                if f.node.abs() > MAX_FRAME_OFFSET {
                    diags.push(
                        Diagnostic::error(format!(
                            "frame offset {} is too far (at most ±{MAX_FRAME_OFFSET})",
                            f.node
                        ))
                        .at(f.span, "too far"),
                    );
                    return None;
                }
            }
            let parts: Vec<&str> = key.parts.iter().map(|p| p.node.as_str()).collect();
            let src = match parts.as_slice() {
                ["IN"] => Source::In { frame: frame_n },
                ["PASS", _] => {
                    if frame_n > 0 {
                        diags.push(
                            Diagnostic::error("a pass output of a later frame is not available")
                                .at(
                                    frame.as_ref().map(|f| f.span).unwrap_or(span),
                                    "only earlier frames (`[-1]`) of a pass output can be read",
                                )
                                .note("later frames can be read from `IN[+n]`"),
                        );
                        return None;
                    }
                    Source::Pass {
                        name: key.parts[1].clone(),
                        frame: frame_n,
                    }
                }
                ["AUX", _] => {
                    if let Some(f) = frame {
                        diags.push(
                            Diagnostic::error(
                                "auxiliary scene inputs have no earlier or later frames",
                            )
                            .at(f.span, "remove the frame offset"),
                        );
                        return None;
                    }
                    Source::Aux {
                        name: key.parts[1].clone(),
                    }
                }
                ["PARAM", _] if frame.is_none() => {
                    return Some(Binding::Param(Spanned::new(
                        ParamArg::Param(key.parts[1].clone()),
                        span,
                    )))
                }
                ["true"] | ["false"] if frame.is_none() => {
                    return Some(Binding::Param(Spanned::new(
                        ParamArg::Literal {
                            value: vec![if parts[0] == "true" { 1.0 } else { 0.0 }],
                            is_bool: true,
                        },
                        span,
                    )))
                }
                [w] if frame.is_none() => {
                    return Some(Binding::Param(Spanned::new(
                        ParamArg::Word(w.to_string()),
                        span,
                    )))
                }
                _ => {
                    diags.push(
                        Diagnostic::error(format!("`{}` is not an input or a parameter value", key.dotted()))
                            .at(span, "expected IN, PASS.name, AUX.name, PARAM.name, a number, a tuple or true/false"),
                    );
                    return None;
                }
            };
            Some(Binding::Input(Spanned::new(src, span)))
        }
        RawValue::Number(_) | RawValue::Tuple(_) => match numbers(&s.value) {
            Some(v) if !v.is_empty() && v.len() <= 4 => Some(Binding::Param(Spanned::new(
                ParamArg::Literal {
                    value: v,
                    is_bool: false,
                },
                span,
            ))),
            _ => {
                diags.push(type_error(
                    s,
                    "a number or a tuple of 2 to 4 numbers",
                    &s.value.node,
                ));
                None
            }
        },
        other => {
            diags.push(type_error(
                s,
                "an input (IN, PASS.name, AUX.name) or a parameter value",
                other,
            ));
            None
        }
    }
}

fn check_out_attr(out: &mut OutSpec, attr: &str, s: &Stmt, diags: &mut Diagnostics) {
    match attr {
        "SIZE" => {
            let Some((w, h)) = pair(s, diags, "a size `(width, height)` in pixels") else { return };
            if w.fract() != 0.0 || h.fract() != 0.0 || w < 0.0 || h < 0.0 {
                diags.push(Diagnostic::error("`OUT.SIZE` takes whole numbers of pixels").at(s.value.span, "not whole pixel counts"));
            } else if w == 0.0 || h == 0.0 {
                diags.push(Diagnostic::error("an output size of 0 pixels").at(s.value.span, "width and height must be at least 1"));
            } else if w > MAX_SIDE as f64 || h > MAX_SIDE as f64 {
                diags.push(
                    Diagnostic::error(format!("output size {}x{} is larger than {MAX_SIDE} px", w, h))
                        .at(s.value.span, format!("at most {MAX_SIDE} on a side")),
                );
            } else {
                out.size = Some(Spanned::new((w as u32, h as u32), s.value.span));
            }
        }
        "SCALE" => {
            let Some((x, y)) = pair(s, diags, "a scale `(sx, sy)` or a single number") else { return };
            if x.is_nan() || y.is_nan() || x <= 0.0 || y <= 0.0 || !x.is_finite() || !y.is_finite() {
                diags.push(
                    Diagnostic::error("an output scale must be positive")
                        .at(s.value.span, "a scale of 0 or less gives an empty texture"),
                );
            } else {
                out.scale = Some(Spanned::new((x, y), s.value.span));
            }
        }
        "RELATIVE_TO" => match word(&s.value) {
            Some(w) => out.relative_to = Some(Spanned::new(w.to_string(), s.value.span)),
            None => diags.push(type_error(s, "the name of one of this pass's inputs", &s.value.node)),
        },
        "FORMAT" => out.format = format_spec(s, diags),
        "COLORSPACE" => out.colorspace = colorspace_value(s, diags),
        _ => diags.push(
            Diagnostic::error(format!("unknown output attribute `OUT.{attr}`"))
                .at(s.key.span, "not an output attribute")
                .note(match suggest(attr, ["SIZE", "SCALE", "RELATIVE_TO", "FORMAT", "COLORSPACE"].into_iter()) {
                    Some(x) => format!("did you mean `OUT.{x}`?"),
                    None => "output attributes: OUT.SIZE, OUT.SCALE, OUT.RELATIVE_TO, OUT.FORMAT, OUT.COLORSPACE".to_string(),
                }),
        ),
    }
    if out.size.is_some() && out.scale.is_some() && matches!(attr, "SIZE" | "SCALE") {
        diags.push(Diagnostic::error("`OUT.SIZE` and `OUT.SCALE` both set").at(
            s.key.span,
            "an output has either an absolute size or a relative scale",
        ));
    }
}

fn check_param_decl(stmt: &Stmt, diags: &mut Diagnostics) -> Option<ParamDecl> {
    if stmt.key.parts.len() != 1 {
        diags.push(
            Diagnostic::error(format!(
                "a parameter name is a single word, found `{}`",
                stmt.key.dotted()
            ))
            .at(stmt.key.span, "expected `name = FLOAT { DEFAULT = 1 }`"),
        );
        return None;
    }
    let name = stmt.key.parts[0].clone();
    let RawValue::Ctor { kind, body } = &stmt.value.node else {
        diags.push(
            Diagnostic::error(format!(
                "parameter `{}` must be declared with a type",
                name.node
            ))
            .at(
                stmt.value.span,
                "expected e.g. `FLOAT { DEFAULT = 0.5  RANGE = (0, 1) }`",
            ),
        );
        return None;
    };
    let mut ty = match kind.dotted().as_str() {
        "FLOAT" => ParamType::Float,
        "INT" => ParamType::Int,
        "BOOL" => ParamType::Bool,
        "VEC2" => ParamType::Vec2,
        "VEC3" => ParamType::Vec3,
        "VEC4" => ParamType::Vec4,
        "ENUM" => ParamType::Enum(Vec::new()),
        other => {
            diags.push(
                Diagnostic::error(format!("unknown parameter type `{other}`")).at(
                    kind.span,
                    "expected FLOAT, INT, BOOL, VEC2, VEC3, VEC4 or ENUM",
                ),
            );
            return None;
        }
    };
    let mut default_raw: Option<&Stmt> = None;
    let mut range = None;
    let mut description = String::new();
    let mut ok = true;
    // VALUES first, so that an ENUM default can be resolved whatever the order.
    for s in body {
        if s.key.is(&["VALUES"]) {
            match (&mut ty, &s.value.node) {
                (ParamType::Enum(values), RawValue::Tuple(items)) => {
                    for it in items {
                        match word(it) {
                            Some(w) => values.push(w.to_string()),
                            None => {
                                diags.push(
                                    Diagnostic::error("enum values are words")
                                        .at(it.span, "expected a word"),
                                );
                                ok = false;
                            }
                        }
                    }
                }
                (ParamType::Enum(_), other) => {
                    diags.push(type_error(s, "a tuple of words `(a, b, c)`", other));
                    ok = false;
                }
                _ => {
                    diags.push(
                        Diagnostic::error("`VALUES` is only for ENUM parameters")
                            .at(s.key.span, "not an ENUM"),
                    );
                    ok = false;
                }
            }
        }
    }
    if let ParamType::Enum(v) = &ty {
        if v.is_empty() {
            diags.push(
                Diagnostic::error(format!("ENUM parameter `{}` has no `VALUES`", name.node))
                    .at(kind.span, "add `VALUES = (a, b)`"),
            );
            return None;
        }
    }
    for s in body {
        match s.key.dotted().as_str() {
            "VALUES" => {}
            "DEFAULT" => default_raw = Some(s),
            "RANGE" => match numbers(&s.value) {
                Some(v) if v.len() == 2 && v[0] <= v[1] => range = Some((v[0], v[1])),
                Some(v) if v.len() == 2 => {
                    diags.push(
                        Diagnostic::error("an empty range: the minimum is above the maximum")
                            .at(s.value.span, "expected `(min, max)` with min <= max"),
                    );
                    ok = false;
                }
                _ => {
                    diags.push(type_error(s, "a range `(min, max)`", &s.value.node));
                    ok = false;
                }
            },
            "DESCRIPTION" => match &s.value.node {
                RawValue::Str(d) => description = d.clone(),
                other => {
                    diags.push(type_error(s, "a string", other));
                    ok = false;
                }
            },
            other => {
                diags.push(
                    Diagnostic::error(format!("unknown parameter attribute `{other}`")).at(
                        s.key.span,
                        "expected DEFAULT, RANGE, DESCRIPTION or (for ENUM) VALUES",
                    ),
                );
                ok = false;
            }
        }
    }
    let Some(def) = default_raw else {
        diags.push(
            Diagnostic::error(format!("parameter `{}` has no `DEFAULT`", name.node))
                .at(name.span, "every parameter needs a default value"),
        );
        return None;
    };
    let arg = match classify_binding(def, diags)? {
        Binding::Param(a) => a,
        Binding::Input(_) => {
            diags.push(Diagnostic::error("a parameter default must be a value").at(
                def.value.span,
                "expected a number, tuple, true/false or word",
            ));
            return None;
        }
    };
    let default = convert_arg(&arg, &ty, range, &name.node, diags)?;
    if !ok {
        return None;
    }
    Some(ParamDecl {
        name,
        ty,
        default,
        range,
        description,
        span: stmt.span,
    })
}

/// Check a literal against a parameter's type and range; returns the numeric value.
pub fn convert_arg(
    arg: &Spanned<ParamArg>,
    ty: &ParamType,
    range: Option<(f64, f64)>,
    param_name: &str,
    diags: &mut Diagnostics,
) -> Option<Value> {
    let value = match (&arg.node, ty) {
        (ParamArg::Word(w), ParamType::Enum(values)) => match values.iter().position(|v| v == w) {
            Some(i) => vec![i as f64],
            None => {
                diags.push(
                    Diagnostic::error(format!("`{w}` is not a value of `{param_name}`"))
                        .at(arg.span, format!("expected one of: {}", values.join(", "))),
                );
                return None;
            }
        },
        (ParamArg::Literal { value, is_bool }, _) => {
            let ok = match ty {
                ParamType::Bool => *is_bool,
                ParamType::Int => !is_bool && value.len() == 1 && value[0].fract() == 0.0,
                ParamType::Float => !is_bool && value.len() == 1,
                ParamType::Enum(_) => false,
                t => !is_bool && value.len() == t.components(),
            };
            if !ok {
                let expected = match ty {
                    ParamType::Float => "a number".to_string(),
                    ParamType::Int => "a whole number".to_string(),
                    ParamType::Bool => "`true` or `false`".to_string(),
                    ParamType::Enum(v) => format!("one of: {}", v.join(", ")),
                    t => format!("a tuple of {} numbers", t.components()),
                };
                diags.push(
                    Diagnostic::error(format!(
                        "wrong type for `{param_name}`: expected {expected}"
                    ))
                    .at(arg.span, format!("`{param_name}` is {}", ty.name())),
                );
                return None;
            }
            value.clone()
        }
        (ParamArg::Word(w), _) => {
            diags.push(
                Diagnostic::error(format!("`{w}` is not a value for `{param_name}`"))
                    .at(arg.span, format!("expected a {} value", ty.name())),
            );
            return None;
        }
        (ParamArg::Param(_), _) => unreachable!("PARAM references are resolved by the caller"),
    };
    if let Some((lo, hi)) = range {
        if value.iter().any(|&x| !(x >= lo && x <= hi)) {
            diags.push(
                Diagnostic::error(format!(
                    "value {} of `{param_name}` is out of range [{}, {}]",
                    format_value(&value),
                    format_value(&[lo]),
                    format_value(&[hi])
                ))
                .at(arg.span, "out of range"),
            );
            return None;
        }
    }
    if value.iter().any(|x| !x.is_finite()) {
        diags.push(
            Diagnostic::error(format!("`{param_name}` must be finite"))
                .at(arg.span, "not a finite number"),
        );
        return None;
    }
    Some(value)
}

impl Key {
    /// Helper used in tests.
    pub fn span_text<'a>(&self, text: &'a str) -> &'a str {
        &text[self.span.start as usize..self.span.end as usize]
    }
}
