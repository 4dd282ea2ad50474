//! `MATERIAL.name = { ... }` definitions: a surface shader and a lighting shader with
//! their settings, checked like effects (every mistake reported with its span, a bad
//! material never stops the checking of the rest of the file).
//!
//! ```text
//! MATERIAL.brick = {
//!     DESCRIPTION = "red brick wall"
//!     SURFACE = SHADER.standard {
//!         base_color_map = "textures/brick.png"
//!         roughness = 0.8
//!         base_color = (0.8, 0.3, 0.2, 1)
//!     }
//!     LIGHTING = SHADER.phong { SPECULAR_POWER = 32 }
//!     ALPHA = opaque
//!     DOUBLE_SIDED = true
//! }
//! ```
//!
//! Setting names inside `SURFACE`/`LIGHTING` are not checked here (they are matched
//! against the shader's fields later); their values are.

use super::ast::{is_new_name, key_name, suggest, type_error, word, Module, SeenKeys};
use super::diag::{Diagnostic, Diagnostics, Span, Spanned};
use super::parse::{RawValue, Stmt};
use super::types::format_value;

/// One `MATERIAL.name = { ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialDef {
    pub name: Spanned<String>,
    pub description: Option<String>,
    /// `SURFACE = SHADER.name { ... }`: what the surface is (colour, normal, ...).
    pub surface: MaterialShader,
    /// `LIGHTING = SHADER.name { ... }`: how lights shade it.
    pub lighting: MaterialShader,
    pub alpha: Option<Spanned<AlphaSpec>>,
    pub alpha_cutoff: Option<Spanned<f64>>,
    pub double_sided: Option<Spanned<bool>>,
    /// The whole `MATERIAL.name = { ... }` statement.
    pub span: Span,
}

/// `ALPHA = opaque | mask | blend`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AlphaSpec {
    Opaque,
    Mask,
    Blend,
}

impl AlphaSpec {
    pub const ALL: [AlphaSpec; 3] = [AlphaSpec::Opaque, AlphaSpec::Mask, AlphaSpec::Blend];

    pub fn name(self) -> &'static str {
        match self {
            AlphaSpec::Opaque => "opaque",
            AlphaSpec::Mask => "mask",
            AlphaSpec::Blend => "blend",
        }
    }

    pub fn from_name(s: &str) -> Option<AlphaSpec> {
        AlphaSpec::ALL.into_iter().find(|a| a.name() == s)
    }
}

/// `SHADER.name { settings }` (or `SHADER.name` without settings).
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialShader {
    /// The shader name (`standard` in `SHADER.standard`), spanning that word.
    pub shader: Spanned<String>,
    pub settings: Vec<MaterialSetting>,
    /// The whole value `SHADER.name { ... }`.
    pub span: Span,
}

impl MaterialShader {
    pub fn setting(&self, name: &str) -> Option<&MaterialSetting> {
        self.settings.iter().find(|s| s.name.node == name)
    }
}

/// `name = value` inside a `SURFACE` or `LIGHTING` block.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialSetting {
    pub name: Spanned<String>,
    pub value: Spanned<MaterialValue>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MaterialValue {
    /// A number, a tuple of 1 to [`MAX_SETTING_NUMBERS`] numbers, or a bool (`true` = 1,
    /// `false` = 0).
    Numbers(Vec<f64>),
    /// A string literal: a texture file path, relative to the file that defines the
    /// material.
    Text(String),
}

/// Most numbers in one setting tuple (a 4x4 matrix).
pub const MAX_SETTING_NUMBERS: usize = 16;

/// The attributes a material may set, in the order the documentation lists them.
pub const MATERIAL_KEYS: [&str; 6] = [
    "DESCRIPTION",
    "SURFACE",
    "LIGHTING",
    "ALPHA",
    "ALPHA_CUTOFF",
    "DOUBLE_SIDED",
];

impl Module {
    /// The material called `name` in this file.
    pub fn material(&self, name: &str) -> Option<&MaterialDef> {
        self.materials.iter().find(|m| m.name.node == name)
    }
}

/// Check a top-level statement whose key starts with `MATERIAL`. `seen` holds the
/// names of the materials before it in the file (also the ones with errors); the
/// definition is returned when its SURFACE and LIGHTING are usable and its name is new.
pub(super) fn check_top_level(
    stmt: &Stmt,
    seen: &mut Vec<Spanned<String>>,
    diags: &mut Diagnostics,
) -> Option<MaterialDef> {
    let name = key_name(
        stmt,
        2,
        "a material is defined as `MATERIAL.name = { ... }`",
        "expected `MATERIAL.name`",
        diags,
    )?;
    let is_new = is_new_name(seen.iter(), &name, "material", "defined", diags);
    if is_new {
        seen.push(name.clone());
    }
    let def = match &stmt.value.node {
        RawValue::Block(body) => check_material(name, body, stmt.span, diags),
        other => {
            diags.push(
                Diagnostic::error(format!(
                    "a material is defined with a block, found {}",
                    other.kind_name()
                ))
                .at(
                    stmt.value.span,
                    "expected `{ SURFACE = SHADER.x { ... } LIGHTING = SHADER.y }`",
                ),
            );
            None
        }
    };
    // A duplicate's body is still checked (its mistakes are reported), then dropped.
    def.filter(|_| is_new)
}

fn check_material(
    name: Spanned<String>,
    body: &[Stmt],
    span: Span,
    diags: &mut Diagnostics,
) -> Option<MaterialDef> {
    let mut attrs = MaterialAttrs::default();
    let mut seen = SeenKeys::new(format!("material `{}`", name.node));
    for stmt in body {
        let k = stmt.key.dotted();
        if !seen.first(&k, stmt.key.span, diags) {
            continue;
        }
        attrs.read(&k, stmt, &name.node, diags);
    }
    let written = |key: &str| seen.contains(key);
    report_missing_shaders(&name, written("SURFACE"), written("LIGHTING"), diags);
    attrs.check_alpha_cutoff(written("ALPHA"), diags);
    Some(MaterialDef {
        name,
        description: attrs.description,
        surface: attrs.surface?,
        lighting: attrs.lighting?,
        alpha: attrs.alpha,
        alpha_cutoff: attrs.alpha_cutoff,
        double_sided: attrs.double_sided,
        span,
    })
}

/// The attributes of a material as they are read.
#[derive(Default)]
struct MaterialAttrs {
    description: Option<String>,
    surface: Option<MaterialShader>,
    lighting: Option<MaterialShader>,
    alpha: Option<Spanned<AlphaSpec>>,
    alpha_cutoff: Option<Spanned<f64>>,
    double_sided: Option<Spanned<bool>>,
}

impl MaterialAttrs {
    /// Attribute `k` of material `material`, written by `stmt`.
    fn read(&mut self, k: &str, stmt: &Stmt, material: &str, diags: &mut Diagnostics) {
        match k {
            "DESCRIPTION" => match &stmt.value.node {
                RawValue::Str(s) => self.description = Some(s.clone()),
                other => diags.push(type_error(stmt, "a string", other)),
            },
            "SURFACE" => self.surface = check_shader(stmt, material, diags),
            "LIGHTING" => self.lighting = check_shader(stmt, material, diags),
            "ALPHA" => self.alpha = alpha_value(stmt, diags),
            "ALPHA_CUTOFF" => match &stmt.value.node {
                RawValue::Number(n) if (0.0..=1.0).contains(n) => {
                    self.alpha_cutoff = Some(Spanned::new(*n, stmt.value.span))
                }
                RawValue::Number(n) => diags.push(
                    Diagnostic::error(format!(
                        "`ALPHA_CUTOFF` must be between 0 and 1, found {}",
                        format_value(&[*n])
                    ))
                    .at(stmt.value.span, "out of range [0, 1]"),
                ),
                other => diags.push(type_error(stmt, "a number between 0 and 1", other)),
            },
            "DOUBLE_SIDED" => match bool_word(&stmt.value) {
                Some(b) => self.double_sided = Some(Spanned::new(b, stmt.value.span)),
                None => diags.push(expected_bool(stmt)),
            },
            _ => {
                let mut d = Diagnostic::error(format!("unknown material attribute `{k}`"))
                    .at(stmt.key.span, "not a material attribute");
                d = match suggest(k, MATERIAL_KEYS.into_iter()) {
                    Some(s) => d.note(format!("did you mean `{s}`?")),
                    None => d.note(format!(
                        "a material may contain {}",
                        MATERIAL_KEYS.join(", ")
                    )),
                };
                diags.push(d);
            }
        }
    }

    /// `ALPHA_CUTOFF` without `ALPHA = mask` is a warning (`alpha_written`:
    /// `ALPHA` was written, even wrongly).
    fn check_alpha_cutoff(&self, alpha_written: bool, diags: &mut Diagnostics) {
        let Some(cutoff) = &self.alpha_cutoff else {
            return;
        };
        let alpha = &self.alpha;
        let is_mask = alpha.as_ref().map(|a| a.node) == Some(AlphaSpec::Mask);
        // A wrongly written ALPHA is reported already; say nothing more about it.
        if !is_mask && (alpha.is_some() || !alpha_written) {
            let mut d = Diagnostic::warning("`ALPHA_CUTOFF` has no effect unless `ALPHA = mask`")
                .at(cutoff.span, "ignored");
            if let Some(a) = alpha {
                d = d.also(a.span, format!("the alpha mode is `{}`", a.node.name()));
            }
            diags.push(d);
        }
    }
}

/// A material needs a `SURFACE` and a `LIGHTING` (written, even wrongly).
fn report_missing_shaders(
    name: &Spanned<String>,
    surface_written: bool,
    lighting_written: bool,
    diags: &mut Diagnostics,
) {
    if !surface_written {
        diags.push(
            Diagnostic::error(format!("material `{}` has no `SURFACE`", name.node))
                .at(
                    name.span,
                    "this material never says which shader draws its surface",
                )
                .note("add e.g. `SURFACE = SHADER.standard { base_color = (1, 1, 1, 1) }`"),
        );
    }
    if !lighting_written {
        diags.push(
            Diagnostic::error(format!("material `{}` has no `LIGHTING`", name.node))
                .at(name.span, "this material never says which shader lights it")
                .note("add e.g. `LIGHTING = SHADER.lambert`"),
        );
    }
}

/// `SURFACE = SHADER.name { ... }` or `LIGHTING = SHADER.name`.
fn check_shader(stmt: &Stmt, material: &str, diags: &mut Diagnostics) -> Option<MaterialShader> {
    let role = stmt.key.dotted();
    let (kind, body, frame) = match &stmt.value.node {
        RawValue::Ctor { kind, body } => (kind, body.as_slice(), None),
        RawValue::Ref { key, frame } => (key, &[][..], frame.as_ref()),
        other => {
            diags.push(type_error(stmt, "a shader `SHADER.name { ... }`", other));
            return None;
        }
    };
    if kind.first() == "EFFECT" {
        diags.push(
            Diagnostic::error(format!(
                "a material's `{role}` is a shader, not an effect: found `{}`",
                kind.dotted()
            ))
            .at(kind.span, "expected `SHADER.<name>`")
            .note("effects are filter graphs over images; a material's SURFACE and LIGHTING are single WGSL shaders"),
        );
        return None;
    }
    if kind.parts.len() != 2 || kind.first() != "SHADER" {
        diags.push(
            Diagnostic::error(format!(
                "`{role}` must be `SHADER.name {{ ... }}`, found `{}`",
                kind.dotted()
            ))
            .at(kind.span, "expected `SHADER.<name>`"),
        );
        return None;
    }
    if let Some(f) = frame {
        diags.push(
            Diagnostic::error("a material shader has no earlier or later frames")
                .at(f.span, "remove the frame offset"),
        );
        return None;
    }
    let mut shader = MaterialShader {
        shader: kind.parts[1].clone(),
        settings: Vec::new(),
        span: stmt.value.span,
    };
    let mut seen = SeenKeys::new(format!("the `{role}` of material `{material}`"));
    for s in body {
        let Some(name) = key_name(
            s,
            1,
            "a shader setting name is a single word",
            "expected `name = value`",
            diags,
        ) else {
            continue;
        };
        if !seen.first(&name.node, s.key.span, diags) {
            continue;
        }
        if let Some(value) = setting_value(s, diags) {
            shader.settings.push(MaterialSetting {
                name,
                value: Spanned::new(value, s.value.span),
            });
        }
    }
    Some(shader)
}

const SETTING_EXPECTED: &str =
    "a number, a tuple of numbers, `true`/`false` or a texture path `\"file.png\"`";

/// The value of one shader setting.
fn setting_value(s: &Stmt, diags: &mut Diagnostics) -> Option<MaterialValue> {
    match &s.value.node {
        RawValue::Number(n) => {
            is_finite_setting(s, *n, s.value.span, diags).then(|| MaterialValue::Numbers(vec![*n]))
        }
        RawValue::Tuple(items) => tuple_setting_value(s, items, diags),
        RawValue::Str(t) if t.is_empty() => {
            diags.push(
                Diagnostic::error(format!("`{}` is an empty texture path", s.key.dotted())).at(
                    s.value.span,
                    "expected a file path such as \"textures/brick.png\"",
                ),
            );
            None
        }
        RawValue::Str(t) => Some(MaterialValue::Text(t.clone())),
        RawValue::Ref { .. } => match bool_word(&s.value) {
            Some(b) => Some(MaterialValue::Numbers(vec![if b { 1.0 } else { 0.0 }])),
            None => {
                report_name_setting(s, diags);
                None
            }
        },
        other => {
            diags.push(type_error(s, SETTING_EXPECTED, other));
            None
        }
    }
}

/// True when number `n` (at `span`) of setting `s` is finite; an error otherwise.
fn is_finite_setting(s: &Stmt, n: f64, span: Span, diags: &mut Diagnostics) -> bool {
    if n.is_finite() {
        true
    } else {
        diags.push(
            Diagnostic::error(format!("`{}` must be finite", s.key.dotted()))
                .at(span, "not a finite number"),
        );
        false
    }
}

/// A setting written as a tuple: finite numbers only, at most
/// [`MAX_SETTING_NUMBERS`] of them.
fn tuple_setting_value(
    s: &Stmt,
    items: &[Spanned<RawValue>],
    diags: &mut Diagnostics,
) -> Option<MaterialValue> {
    let mut out = Vec::with_capacity(items.len());
    let mut ok = true;
    for it in items {
        match &it.node {
            RawValue::Number(n) => {
                ok &= is_finite_setting(s, *n, it.span, diags);
                out.push(*n);
            }
            other => {
                let found = match other {
                    RawValue::Ref { .. } => format!("`{}`", text_of_ref(other)),
                    o => o.kind_name().to_string(),
                };
                diags.push(
                    Diagnostic::error(format!(
                        "a tuple in `{}` holds numbers only, found {found}",
                        s.key.dotted()
                    ))
                    .at(it.span, "expected a number"),
                );
                ok = false;
            }
        }
    }
    if items.len() > MAX_SETTING_NUMBERS {
        diags.push(
            Diagnostic::error(format!(
                "a tuple of {} numbers in `{}`: at most {MAX_SETTING_NUMBERS} (a 4x4 matrix)",
                items.len(),
                s.key.dotted()
            ))
            .at(s.value.span, "too many numbers"),
        );
        ok = false;
    }
    ok.then_some(MaterialValue::Numbers(out))
}

/// A setting written as a name other than `true`/`false`: an effect's image
/// or parameter, or a texture path without its quotes.
fn report_name_setting(s: &Stmt, diags: &mut Diagnostics) {
    let r = text_of_ref(&s.value.node);
    let mut d = Diagnostic::error(format!(
        "`{}` expects {SETTING_EXPECTED}, found `{r}`",
        s.key.dotted()
    ))
    .at(s.value.span, "not a material setting value");
    let first = match &s.value.node {
        RawValue::Ref { key, .. } => key.first(),
        _ => "",
    };
    d = if ["IN", "PASS", "AUX", "PARAM"].contains(&first) {
        d.note("a material reads no images or parameters of an effect; textures are file paths in quotes")
    } else {
        d.note(format!("a texture path is written in quotes: `\"{r}\"`"))
    };
    diags.push(d);
}

/// `PASS.x`, `IN[-1]`, `word` as written.
fn text_of_ref(v: &RawValue) -> String {
    match v {
        RawValue::Ref { key, frame } => match frame {
            Some(f) if f.node > 0 => format!("{}[+{}]", key.dotted(), f.node),
            Some(f) => format!("{}[{}]", key.dotted(), f.node),
            None => key.dotted(),
        },
        _ => String::new(),
    }
}

fn bool_word(v: &Spanned<RawValue>) -> Option<bool> {
    match word(v) {
        Some("true") => Some(true),
        Some("false") => Some(false),
        _ => None,
    }
}

fn expected_bool(stmt: &Stmt) -> Diagnostic {
    let found = match &stmt.value.node {
        r @ RawValue::Ref { .. } => format!("`{}`", text_of_ref(r)),
        other => other.kind_name().to_string(),
    };
    Diagnostic::error(format!(
        "`{}` expects `true` or `false`, found {found}",
        stmt.key.dotted()
    ))
    .at(stmt.value.span, "expected `true` or `false`")
}

fn alpha_value(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<AlphaSpec>> {
    let Some(w) = word(&stmt.value) else {
        diags.push(type_error(
            stmt,
            "`opaque`, `mask` or `blend`",
            &stmt.value.node,
        ));
        return None;
    };
    if let Some(a) = AlphaSpec::from_name(w) {
        return Some(Spanned::new(a, stmt.value.span));
    }
    let mut d = Diagnostic::error(format!("unknown alpha mode `{w}`"))
        .at(stmt.value.span, "expected `opaque`, `mask` or `blend`");
    if let Some(s) = suggest(w, AlphaSpec::ALL.iter().map(|a| a.name())) {
        d = d.note(format!("did you mean `{s}`?"));
    }
    diags.push(d);
    None
}

#[cfg(test)]
#[path = "material_tests.rs"]
mod tests;
