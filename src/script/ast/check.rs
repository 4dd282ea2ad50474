//! The checker's entry: a file's items into effects and materials, each effect's
//! attributes, and the references between its passes.

use super::*;
use crate::script::diag::{Diagnostic, Diagnostics, FileId, Span, Spanned};
use crate::script::jitter::JitterPattern;
use crate::script::material;
use crate::script::parse::{Item, RawValue, Stmt};

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
                    if !is_new_name(
                        module.effects.iter().map(|e| &e.name),
                        &name,
                        "effect",
                        "defined",
                        diags,
                    ) {
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
        jitter: None,
        span,
    };
    let mut seen = SeenKeys::new(format!("effect `{}`", e.name.node));
    // `OUT = ...` was written (even if wrongly): no "missing OUT" error then.
    let mut out_written = false;
    for stmt in body {
        let k = stmt.key.dotted();
        out_written |= k == "OUT";
        if !seen.first(&k, stmt.key.span, diags) {
            continue;
        }
        match k.as_str() {
            "PASS" => add_passes(&mut e, stmt, diags),
            "PARAM" => add_params(&mut e, stmt, diags),
            "OUT" => {
                if let Some(out) = effect_out(stmt, diags) {
                    e.out = Some(out);
                }
            }
            "DESCRIPTION" => match &stmt.value.node {
                RawValue::Str(s) => e.description = Some(s.clone()),
                other => diags.push(type_error(stmt, "a string", other)),
            },
            "FORMAT" => e.format = format_spec(stmt, diags),
            "COLORSPACE" => e.colorspace = colorspace_value(stmt, diags),
            "JITTER" => e.jitter = jitter_value(stmt, diags),
            _ => diags.push(
                Diagnostic::error(format!("unknown effect attribute `{k}`"))
                    .at(stmt.key.span, "not an effect attribute")
                    .note("an effect may contain PASS, OUT, PARAM, DESCRIPTION, FORMAT, COLORSPACE and JITTER"),
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

/// The passes of a `PASS { ... }` block, each name once.
fn add_passes(e: &mut EffectDef, stmt: &Stmt, diags: &mut Diagnostics) {
    match &stmt.value.node {
        RawValue::Block(passes) => {
            for p in passes {
                if let Some(pass) = check_pass(p, diags) {
                    if is_new_name(
                        e.passes.iter().map(|q| &q.name),
                        &pass.name,
                        "pass",
                        "defined",
                        diags,
                    ) {
                        e.passes.push(pass);
                    }
                }
            }
        }
        other => diags.push(type_error(
            stmt,
            "a block of passes `{ name = SHADER.x { ... } }`",
            other,
        )),
    }
}

/// The parameters of a `PARAM { ... }` block, each name once.
fn add_params(e: &mut EffectDef, stmt: &Stmt, diags: &mut Diagnostics) {
    match &stmt.value.node {
        RawValue::Block(params) => {
            for p in params {
                if let Some(decl) = check_param_decl(p, diags) {
                    if is_new_name(
                        e.params.iter().map(|q| &q.name),
                        &decl.name,
                        "parameter",
                        "declared",
                        diags,
                    ) {
                        e.params.push(decl);
                    }
                }
            }
        }
        other => diags.push(type_error(stmt, "a block of parameter declarations", other)),
    }
}

/// What `OUT = ...` names: `IN`, or a pass (`final`, `PASS.final`).
fn effect_out(stmt: &Stmt, diags: &mut Diagnostics) -> Option<OutRef> {
    match &stmt.value.node {
        RawValue::Ref { key, frame } => {
            if let Some(f) = frame {
                diags.push(
                    Diagnostic::error("the effect output cannot be an earlier or later frame")
                        .at(f.span, "remove the frame offset"),
                );
                None
            } else if key.is(&["IN"]) {
                Some(OutRef::In(key.span))
            } else if key.parts.len() == 1 {
                Some(OutRef::Pass(key.parts[0].clone()))
            } else if key.parts.len() == 2 && key.first() == "PASS" {
                Some(OutRef::Pass(key.parts[1].clone()))
            } else {
                diags.push(
                    Diagnostic::error(format!("`OUT` must name a pass, found `{}`", key.dotted()))
                        .at(
                            key.span,
                            "expected a pass name such as `final` or `PASS.final`",
                        ),
                );
                None
            }
        }
        other => {
            diags.push(type_error(stmt, "a pass name", other));
            None
        }
    }
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
            let (x, y) = &rel.node;
            let unknown = [x, y].into_iter().find(|n| {
                *n != "IN" && *n != VIEWPORT && !p.inputs.iter().any(|i| i.name.node == **n)
            });
            if let Some(name) = unknown {
                diags.push(
                    Diagnostic::error(format!(
                        "`OUT.RELATIVE_TO` names `{}`, which is not an input of pass `{}`",
                        name, p.name.node
                    ))
                    .at(rel.span, "not an input of this pass")
                    .note("an input of the pass, IN for the effect's input, or VIEWPORT for the run's output size"),
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

pub(super) fn format_spec(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<FormatSpec>> {
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

pub(super) fn colorspace_value(
    stmt: &Stmt,
    diags: &mut Diagnostics,
) -> Option<Spanned<ColorSpace>> {
    match word(&stmt.value) {
        Some(w) => match ColorSpace::from_name(w) {
            Some(c) => Some(Spanned::new(c, stmt.value.span)),
            None => {
                diags.push(
                    Diagnostic::error(format!("unknown colour space `{w}`"))
                        .at(stmt.value.span, "expected `linear`, `srgb` or `stored`"),
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

/// `JITTER = halton23`.
fn jitter_value(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<JitterPattern>> {
    let names: Vec<&str> = JitterPattern::ALL.iter().map(|p| p.name()).collect();
    match word(&stmt.value) {
        Some(w) => match JitterPattern::from_name(w) {
            Some(p) => Some(Spanned::new(p, stmt.value.span)),
            None => {
                let mut d = Diagnostic::error(format!("unknown jitter sequence `{w}`"))
                    .at(stmt.value.span, "not a jitter sequence");
                d = match suggest(w, names.iter().copied()) {
                    Some(s) => d.note(format!("did you mean `{s}`?")),
                    None => d.note(format!("jitter sequences: {}", names.join(", "))),
                };
                diags.push(d);
                None
            }
        },
        None => {
            diags.push(type_error(
                stmt,
                "a jitter sequence name (`halton23`)",
                &stmt.value.node,
            ));
            None
        }
    }
}

/// Numbers of a number or tuple of numbers.
pub(super) fn numbers(v: &Spanned<RawValue>) -> Option<Vec<f64>> {
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

pub(super) fn pair(stmt: &Stmt, diags: &mut Diagnostics, what: &str) -> Option<(f64, f64)> {
    match numbers(&stmt.value) {
        Some(v) if v.len() == 2 => Some((v[0], v[1])),
        Some(v) if v.len() == 1 && stmt.key.dotted() == "OUT.SCALE" => Some((v[0], v[0])),
        _ => {
            diags.push(type_error(stmt, what, &stmt.value.node));
            None
        }
    }
}

pub(crate) fn type_error(stmt: &Stmt, expected: &str, found: &RawValue) -> Diagnostic {
    Diagnostic::error(format!(
        "`{}` expects {expected}, found {}",
        stmt.key.dotted(),
        found.kind_name()
    ))
    .at(stmt.value.span, format!("expected {expected}"))
}

pub(crate) fn word(v: &Spanned<RawValue>) -> Option<&str> {
    match &v.node {
        RawValue::Ref { key, frame: None } if key.parts.len() == 1 => Some(key.first()),
        _ => None,
    }
}
