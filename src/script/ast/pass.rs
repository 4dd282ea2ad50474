//! Checking a `PASS` entry: its kind, inputs, parameters, defines and output.

use super::*;
use crate::script::diag::{Diagnostic, Diagnostics, Spanned};
use crate::script::parse::{Key, RawValue, Stmt};

pub(super) fn check_pass(stmt: &Stmt, diags: &mut Diagnostics) -> Option<PassDef> {
    let name = pass_name(stmt, diags)?;
    let (kind, body) = pass_kind(stmt, &name, diags)?;
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
    let mut seen = SeenKeys::new(format!("pass `{}`", pass.name.node));
    // Sampling attributes refer to inputs that may be bound later in the block.
    let mut sampling: Vec<&Stmt> = Vec::new();
    for s in body {
        if !seen.first(&s.key.dotted(), s.key.span, diags) {
            continue;
        }
        let parts: Vec<&str> = s.key.parts.iter().map(|p| p.node.as_str()).collect();
        match parts.as_slice() {
            ["OUT", _] => check_pass_attr(&mut pass, is_effect, s, diags),
            ["DEFINE", _] if !is_effect => check_pass_attr(&mut pass, is_effect, s, diags),
            [_input, "FILTER" | "WRAP" | "MIPMAP" | "COLORSPACE"] => sampling.push(s),
            _ => check_pass_attr(&mut pass, is_effect, s, diags),
        }
    }
    for s in sampling {
        check_sampling_attr(&mut pass, s, diags);
    }
    Some(pass)
}

/// The pass's name: one word, not a reserved one.
fn pass_name(stmt: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<String>> {
    let name = key_name(
        stmt,
        1,
        "a pass name is a single word",
        "expected `name = SHADER.shader { ... }`",
        diags,
    )?;
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
    Some(name)
}

/// What the pass runs (`SHADER.name` or `EFFECT.name`) and its body.
fn pass_kind<'s>(
    stmt: &'s Stmt,
    name: &Spanned<String>,
    diags: &mut Diagnostics,
) -> Option<(PassKind, &'s [Stmt])> {
    match &stmt.value.node {
        RawValue::Ctor { kind, body } if kind.parts.len() == 2 && kind.first() == "SHADER" => {
            Some((PassKind::Shader(kind.parts[1].clone()), body))
        }
        RawValue::Ctor { kind, body } if kind.parts.len() == 2 && kind.first() == "EFFECT" => {
            Some((PassKind::Effect(kind.parts[1].clone()), body))
        }
        RawValue::Ctor { kind, .. } => {
            diags.push(
                Diagnostic::error(format!(
                    "a pass is `SHADER.name {{ ... }}` or `EFFECT.name {{ ... }}`, found `{}`",
                    kind.dotted()
                ))
                .at(kind.span, "expected SHADER.<name> or EFFECT.<name>"),
            );
            None
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
            None
        }
    }
}

/// One entry of the pass's body other than a sampling attribute: `OUT.*`,
/// `DEFINE.*`, or an input or parameter binding.
fn check_pass_attr(pass: &mut PassDef, is_effect: bool, s: &Stmt, diags: &mut Diagnostics) {
    let parts: Vec<&str> = s.key.parts.iter().map(|p| p.node.as_str()).collect();
    match parts.as_slice() {
        ["OUT", attr] if !is_effect => check_out_attr(&mut pass.out, attr, s, diags),
        ["OUT", _] => diags.push(
            Diagnostic::error("an effect instance takes its output size and format from the effect itself")
                .at(s.key.span, "`OUT.*` is not allowed on `EFFECT.` passes"),
        ),
        ["DEFINE", _] if !is_effect => match define_arg(&s.value.node) {
            Some(v) => pass.defines.push(DefineSet {
                name: s.key.parts[1].clone(),
                value: Spanned::new(v, s.value.span),
            }),
            None => diags.push(type_error(s, "an integer, `true`, `false` or `PARAM.name`", &s.value.node)),
        },
        [single] => {
            let name = s.key.parts[0].clone();
            if *single == "IN" && !is_effect {
                diags.push(
                    Diagnostic::error("`IN` names the effect input; a shader input needs its own name")
                        .at(s.key.span, "write e.g. `img = IN`"),
                );
                return;
            }
            match classify_binding(s, diags) {
                Some(Binding::Input(source)) => pass.inputs.push(InputDef {
                    name,
                    source,
                    filter: None,
                    wrap: None,
                    colorspace: None,
                    mipmap: None,
                }),
                Some(Binding::Param(value)) => pass.params.push(ParamSet { name, value }),
                None => {}
            }
        }
        _ => diags.push(
            Diagnostic::error(format!("unknown pass attribute `{}`", s.key.dotted()))
                .at(s.key.span, "not a pass attribute")
                .note("a pass contains inputs (`img = IN`), parameters (`threshold = 0.8`), `img.FILTER`, `img.WRAP`, `img.MIPMAP`, `img.COLORSPACE`, `OUT.SIZE`, `OUT.WIDTH`, `OUT.HEIGHT`, `OUT.SCALE`, `OUT.RELATIVE_TO`, `OUT.FORMAT`, `OUT.COLORSPACE` and `DEFINE.NAME`"),
        ),
    }
}

/// The value of a `DEFINE.NAME`: an integer, `true`, `false` or `PARAM.name`.
fn define_arg(value: &RawValue) -> Option<DefineArg> {
    match value {
        RawValue::Number(n) if n.fract() == 0.0 && n.abs() < 1e15 => {
            Some(DefineArg::Int(*n as i64))
        }
        RawValue::Ref { key, frame: None } if key.is(&["true"]) => Some(DefineArg::Int(1)),
        RawValue::Ref { key, frame: None } if key.is(&["false"]) => Some(DefineArg::Int(0)),
        RawValue::Ref { key, frame: None } if key.parts.len() == 2 && key.first() == "PARAM" => {
            Some(DefineArg::Param(key.parts[1].clone()))
        }
        _ => None,
    }
}

/// `img.FILTER`, `img.WRAP`, `img.MIPMAP` or `img.COLORSPACE` of an input bound
/// in the pass.
fn check_sampling_attr(pass: &mut PassDef, s: &Stmt, diags: &mut Diagnostics) {
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
        return;
    };
    match attr {
        "FILTER" => match word(&s.value).and_then(Filter::from_name) {
            Some(f) => input.filter = Some(Spanned::new(f, s.value.span)),
            None => diags.push(
                Diagnostic::error("unknown filter")
                    .at(s.value.span, "expected `linear` or `nearest`"),
            ),
        },
        "WRAP" => match wrap_modes(&s.value) {
            Some(w) => input.wrap = Some(Spanned::new(w, s.value.span)),
            None => diags.push(Diagnostic::error("unknown wrap mode").at(
                s.value.span,
                "expected `clamp`, `repeat`, `mirror`, `border` or a pair `(u, v)` of them",
            )),
        },
        "MIPMAP" => match word(&s.value) {
            Some("true") => input.mipmap = Some(Spanned::new(true, s.value.span)),
            Some("false") => input.mipmap = Some(Spanned::new(false, s.value.span)),
            _ => diags.push(
                Diagnostic::error("`MIPMAP` takes `true` or `false`")
                    .at(s.value.span, "expected `true` or `false`"),
            ),
        },
        _ => input.colorspace = colorspace_value(s, diags),
    }
}

/// `OUT.RELATIVE_TO`'s names: one word for both axes, or a pair `(x, y)`.
fn relative_to_names(v: &Spanned<RawValue>) -> Option<(String, String)> {
    match &v.node {
        RawValue::Tuple(items) if items.len() == 2 => {
            Some((word(&items[0])?.to_string(), word(&items[1])?.to_string()))
        }
        _ => word(v).map(|w| (w.to_string(), w.to_string())),
    }
}

/// The wrap modes of `img.WRAP`: one for both axes, or a pair `(u, v)`.
fn wrap_modes(value: &Spanned<RawValue>) -> Option<(Wrap, Wrap)> {
    match &value.node {
        RawValue::Tuple(items) if items.len() == 2 => {
            match (
                word(&items[0]).and_then(Wrap::from_name),
                word(&items[1]).and_then(Wrap::from_name),
            ) {
                (Some(u), Some(v)) => Some((u, v)),
                _ => None,
            }
        }
        _ => word(value).and_then(Wrap::from_name).map(|w| (w, w)),
    }
}

pub(super) enum Binding {
    Input(Spanned<Source>),
    Param(Spanned<ParamArg>),
}

pub(super) fn classify_binding(s: &Stmt, diags: &mut Diagnostics) -> Option<Binding> {
    let span = s.value.span;
    match &s.value.node {
        RawValue::Ref { key, frame } => classify_ref(key, frame.as_ref(), span, diags),
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

/// A binding written as a name (`IN[-1]`, `PASS.x`, `AUX.x`, `PARAM.x`,
/// `true`, a word), with its frame offset if any.
fn classify_ref(
    key: &Key,
    frame: Option<&Spanned<i32>>,
    span: Span,
    diags: &mut Diagnostics,
) -> Option<Binding> {
    let frame_n = frame.map(|f| f.node).unwrap_or(0);
    if let Some(f) = frame {
        if f.node.unsigned_abs() > MAX_FRAME_OFFSET.unsigned_abs() {
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
    let param = |arg: ParamArg| Some(Binding::Param(Spanned::new(arg, span)));
    let src = match parts.as_slice() {
        ["IN"] => Source::In { frame: frame_n },
        ["PASS", _] => {
            if frame_n > 0 {
                diags.push(
                    Diagnostic::error("a pass output of a later frame is not available")
                        .at(
                            frame.map(|f| f.span).unwrap_or(span),
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
                    Diagnostic::error("auxiliary scene inputs have no earlier or later frames")
                        .at(f.span, "remove the frame offset"),
                );
                return None;
            }
            Source::Aux {
                name: key.parts[1].clone(),
            }
        }
        ["PARAM", _] if frame.is_none() => return param(ParamArg::Param(key.parts[1].clone())),
        ["true"] | ["false"] if frame.is_none() => {
            return param(ParamArg::Literal {
                value: vec![if parts[0] == "true" { 1.0 } else { 0.0 }],
                is_bool: true,
            })
        }
        [w] if frame.is_none() => return param(ParamArg::Word(w.to_string())),
        _ => {
            diags.push(
                Diagnostic::error(format!(
                    "`{}` is not an input or a parameter value",
                    key.dotted()
                ))
                .at(
                    span,
                    "expected IN, PASS.name, AUX.name, PARAM.name, a number, a tuple or true/false",
                ),
            );
            return None;
        }
    };
    Some(Binding::Input(Spanned::new(src, span)))
}

fn check_out_attr(out: &mut OutSpec, attr: &str, s: &Stmt, diags: &mut Diagnostics) {
    match attr {
        "SIZE" => {
            let Some((w, h)) = pair(s, diags, "a size `(width, height)` in pixels") else { return };
            if let Some(v) = pixel_counts(&[w, h], s, diags) {
                out.size = Some(Spanned::new((v[0], v[1]), s.value.span));
            }
        }
        "WIDTH" | "HEIGHT" => {
            let Some(n) = one_number(s, diags) else { return };
            if let Some(v) = pixel_counts(&[n], s, diags) {
                let axis = if attr == "WIDTH" { &mut out.width } else { &mut out.height };
                *axis = Some(Spanned::new(v[0], s.value.span));
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
        "RELATIVE_TO" => match relative_to_names(&s.value) {
            Some(names) => out.relative_to = Some(Spanned::new(names, s.value.span)),
            None => diags.push(type_error(
                s,
                "the name of one of this pass's inputs (or `IN`, or `VIEWPORT`), or a pair `(width's, height's)`",
                &s.value.node,
            )),
        },
        "FORMAT" => out.format = format_spec(s, diags),
        "COLORSPACE" => out.colorspace = colorspace_value(s, diags),
        _ => diags.push(
            Diagnostic::error(format!("unknown output attribute `OUT.{attr}`"))
                .at(s.key.span, "not an output attribute")
                .note(match suggest(attr, OUT_ATTRIBUTES.into_iter()) {
                    Some(x) => format!("did you mean `OUT.{x}`?"),
                    None => format!("output attributes: OUT.{}", OUT_ATTRIBUTES.join(", OUT.")),
                }),
        ),
    }
    check_size_attrs_agree(out, attr, s, diags);
}

const OUT_ATTRIBUTES: [&str; 7] = [
    "SIZE",
    "WIDTH",
    "HEIGHT",
    "SCALE",
    "RELATIVE_TO",
    "FORMAT",
    "COLORSPACE",
];

/// Whole, positive numbers of pixels no larger than `MAX_SIDE` (`OUT.SIZE`'s
/// two, `OUT.WIDTH`'s one), or the one error they make.
fn pixel_counts(v: &[f64], s: &Stmt, diags: &mut Diagnostics) -> Option<Vec<u32>> {
    let what = s.key.dotted();
    let shown = v
        .iter()
        .map(|n| n.to_string())
        .collect::<Vec<_>>()
        .join("x");
    if v.iter().any(|n| n.fract() != 0.0 || *n < 0.0 || n.is_nan()) {
        diags.push(
            Diagnostic::error(format!("`{what}` takes whole numbers of pixels"))
                .at(s.value.span, "not whole pixel counts"),
        );
    } else if v.contains(&0.0) {
        diags.push(
            Diagnostic::error("an output size of 0 pixels")
                .at(s.value.span, "width and height must be at least 1"),
        );
    } else if v.iter().any(|n| *n > MAX_SIDE as f64) {
        diags.push(
            Diagnostic::error(format!("output size {shown} is larger than {MAX_SIDE} px"))
                .at(s.value.span, format!("at most {MAX_SIDE} on a side")),
        );
    } else {
        return Some(v.iter().map(|n| *n as u32).collect());
    }
    None
}

/// The single number of `OUT.WIDTH = 640`.
fn one_number(s: &Stmt, diags: &mut Diagnostics) -> Option<f64> {
    match &s.value.node {
        RawValue::Number(n) => Some(*n),
        other => {
            diags.push(type_error(s, "a number of pixels", other));
            None
        }
    }
}

/// `OUT.SIZE` fixes both axes, so it excludes `OUT.SCALE`, `OUT.WIDTH` and
/// `OUT.HEIGHT`; `OUT.WIDTH` with `OUT.HEIGHT` leaves `OUT.SCALE` no axis.
fn check_size_attrs_agree(out: &OutSpec, attr: &str, s: &Stmt, diags: &mut Diagnostics) {
    if !matches!(attr, "SIZE" | "SCALE" | "WIDTH" | "HEIGHT") {
        return;
    }
    let size = out.size.is_some();
    let axes = out.width.is_some() || out.height.is_some();
    if size && axes && attr != "SCALE" {
        diags.push(
            Diagnostic::error("`OUT.SIZE` with `OUT.WIDTH` or `OUT.HEIGHT`").at(
                s.key.span,
                "OUT.SIZE sets both axes; OUT.WIDTH and OUT.HEIGHT set one each",
            ),
        );
    }
    if out.width.is_some() && out.height.is_some() && out.scale.is_some() && attr != "SIZE" {
        diags.push(
            Diagnostic::error("`OUT.SCALE` with both `OUT.WIDTH` and `OUT.HEIGHT`").at(
                s.key.span,
                "both axes are in pixels: the scale has no axis to scale",
            ),
        );
    }
    if out.size.is_some() && out.scale.is_some() && matches!(attr, "SIZE" | "SCALE") {
        diags.push(Diagnostic::error("`OUT.SIZE` and `OUT.SCALE` both set").at(
            s.key.span,
            "an output has either an absolute size or a relative scale",
        ));
    }
}
