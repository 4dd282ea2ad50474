//! Checking a `PARAM` declaration and converting arguments to its type.

use super::*;
use crate::script::diag::{Diagnostic, Diagnostics, Spanned};
use crate::script::parse::{Key, RawValue, Stmt};

pub(super) fn check_param_decl(stmt: &Stmt, diags: &mut Diagnostics) -> Option<ParamDecl> {
    let name = key_name(
        stmt,
        1,
        "a parameter name is a single word",
        "expected `name = FLOAT { DEFAULT = 1 }`",
        diags,
    )?;
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
    let mut ty = param_type(kind, diags)?;
    // VALUES first, so that an ENUM default can be resolved whatever the order.
    let values_ok = read_enum_values(&mut ty, body, diags);
    if let ParamType::Enum(v) = &ty {
        if v.is_empty() {
            diags.push(
                Diagnostic::error(format!("ENUM parameter `{}` has no `VALUES`", name.node))
                    .at(kind.span, "add `VALUES = (a, b)`"),
            );
            return None;
        }
    }
    let attrs = read_param_attrs(body, diags);
    let Some(def) = attrs.default else {
        diags.push(
            Diagnostic::error(format!("parameter `{}` has no `DEFAULT`", name.node))
                .at(name.span, "every parameter needs a default value"),
        );
        return None;
    };
    let arg = default_arg(def, diags)?;
    let default = convert_arg(&arg, &ty, attrs.range, &name.node, diags)?;
    if !(values_ok && attrs.ok) {
        return None;
    }
    Some(ParamDecl {
        name,
        ty,
        default,
        range: attrs.range,
        step: attrs.step,
        description: attrs.description,
        span: stmt.span,
    })
}

/// The parameter type a declaration names (`FLOAT`, ..., `ENUM`).
fn param_type(kind: &Key, diags: &mut Diagnostics) -> Option<ParamType> {
    Some(match kind.dotted().as_str() {
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
    })
}

/// The `VALUES` of an ENUM parameter, added to `ty`; false after an error
/// (`VALUES` on another type, values that are not words).
fn read_enum_values(ty: &mut ParamType, body: &[Stmt], diags: &mut Diagnostics) -> bool {
    let mut ok = true;
    for s in body {
        if !s.key.is(&["VALUES"]) {
            continue;
        }
        match (&mut *ty, &s.value.node) {
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
    ok
}

/// The attributes of a parameter declaration other than `VALUES`.
struct ParamAttrs<'s> {
    default: Option<&'s Stmt>,
    range: Option<(f64, f64)>,
    step: Option<f64>,
    description: String,
    /// False after an error in one of them.
    ok: bool,
}

/// `DEFAULT` (kept as written), `RANGE`, `STEP` and `DESCRIPTION`; others are
/// errors.
fn read_param_attrs<'s>(body: &'s [Stmt], diags: &mut Diagnostics) -> ParamAttrs<'s> {
    let mut attrs = ParamAttrs {
        default: None,
        range: None,
        step: None,
        description: String::new(),
        ok: true,
    };
    for s in body {
        match s.key.dotted().as_str() {
            "VALUES" => {}
            "DEFAULT" => attrs.default = Some(s),
            "RANGE" => match numbers(&s.value) {
                Some(v) if v.len() == 2 && v[0] <= v[1] => attrs.range = Some((v[0], v[1])),
                Some(v) if v.len() == 2 => {
                    diags.push(
                        Diagnostic::error("an empty range: the minimum is above the maximum")
                            .at(s.value.span, "expected `(min, max)` with min <= max"),
                    );
                    attrs.ok = false;
                }
                _ => {
                    diags.push(type_error(s, "a range `(min, max)`", &s.value.node));
                    attrs.ok = false;
                }
            },
            "STEP" => match numbers(&s.value).as_deref() {
                Some(&[v]) if v > 0.0 && v.is_finite() => attrs.step = Some(v),
                _ => {
                    diags.push(type_error(s, "a positive number", &s.value.node));
                    attrs.ok = false;
                }
            },
            "DESCRIPTION" => match &s.value.node {
                RawValue::Str(d) => attrs.description = d.clone(),
                other => {
                    diags.push(type_error(s, "a string", other));
                    attrs.ok = false;
                }
            },
            other => {
                diags.push(
                    Diagnostic::error(format!("unknown parameter attribute `{other}`")).at(
                        s.key.span,
                        "expected DEFAULT, RANGE, STEP, DESCRIPTION or (for ENUM) VALUES",
                    ),
                );
                attrs.ok = false;
            }
        }
    }
    attrs
}

/// The `DEFAULT` entry's value: a value, not an input.
fn default_arg(def: &Stmt, diags: &mut Diagnostics) -> Option<Spanned<ParamArg>> {
    match classify_binding(def, diags)? {
        Binding::Param(a) => Some(a),
        Binding::Input(_) => {
            diags.push(Diagnostic::error("a parameter default must be a value").at(
                def.value.span,
                "expected a number, tuple, true/false or word",
            ));
            None
        }
    }
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
