//! naga's messages in WGSL terms: its `Debug` type forms written as WGSL type names
//! (`vec3<f32>`, a struct by its name, `ptr<function, Light>`), its operator names
//! as the WGSL operators.

use naga::common::wgsl::TypeContext as _;
use naga::{ScalarKind, TypeInner};

/// [`sanitize`] knowing the module the message is about: the `Debug` forms of its
/// types (a struct's `Struct { members: [...], span: N }`, arrays, atomics, images,
/// samplers) and of pointers to them are written by their WGSL names (the struct's
/// own name), before the module-free forms of [`sanitize`].
pub fn sanitize_in(msg: &str, module: &naga::Module) -> String {
    if !msg.contains('{') && !msg.contains('(') {
        return sanitize(msg);
    }
    let types = &module.types;
    let wgsl = |inner: &TypeInner| {
        let mut s = String::new();
        let _ = types.write_type_inner(inner, &mut s);
        s
    };
    let mut pairs: Vec<(String, String)> = Vec::new();
    for (h, ty) in types.iter() {
        if !matches!(ty.inner, TypeInner::Scalar(_) | TypeInner::Vector { .. }) {
            pairs.push((format!("{:?}", ty.inner), types.type_to_string(h)));
        }
        for space in ADDRESS_SPACES {
            let p = TypeInner::Pointer { base: h, space };
            pairs.push((format!("{p:?}"), wgsl(&p)));
        }
    }
    pairs.sort_by_key(|(d, _)| std::cmp::Reverse(d.len()));
    let mut s = msg.to_string();
    for (debug, name) in &pairs {
        if s.contains(debug.as_str()) {
            s = s.replace(debug.as_str(), name);
        }
    }
    sanitize(&s)
}

/// The address spaces a pointer of a message may be in.
const ADDRESS_SPACES: [naga::AddressSpace; 7] = [
    naga::AddressSpace::Function,
    naga::AddressSpace::Private,
    naga::AddressSpace::WorkGroup,
    naga::AddressSpace::Uniform,
    naga::AddressSpace::Storage {
        access: naga::StorageAccess::LOAD,
    },
    naga::AddressSpace::Storage {
        access: naga::StorageAccess::LOAD.union(naga::StorageAccess::STORE),
    },
    naga::AddressSpace::Handle,
];

/// naga's operator names (`Operation And can't work with ...`) and the WGSL
/// operators.
const OPERATORS: [(&str, &str); 21] = [
    ("Add", "+"),
    ("Subtract", "-"),
    ("Multiply", "*"),
    ("Divide", "/"),
    ("Modulo", "%"),
    ("Equal", "=="),
    ("NotEqual", "!="),
    ("Less", "<"),
    ("LessEqual", "<="),
    ("Greater", ">"),
    ("GreaterEqual", ">="),
    ("And", "&"),
    ("ExclusiveOr", "^"),
    ("InclusiveOr", "|"),
    ("LogicalAnd", "&&"),
    ("LogicalOr", "||"),
    ("ShiftLeft", "<<"),
    ("ShiftRight", ">>"),
    ("Negate", "-"),
    ("LogicalNot", "!"),
    ("BitwiseNot", "~"),
];

/// `Operation And can't work with` → ``operator `&` can't work with``.
fn operator_names(msg: &str) -> String {
    let Some(rest) = msg.strip_prefix("Operation ") else {
        return msg.to_string();
    };
    let Some((name, tail)) = rest.split_once(' ') else {
        return msg.to_string();
    };
    match OPERATORS.iter().find(|(n, _)| *n == name) {
        Some((_, op)) if tail.starts_with("can't work with") => {
            format!("operator `{op}` {tail}")
        }
        _ => msg.to_string(),
    }
}

/// A struct's `Debug` form that no module named (`Struct { members:
/// [StructMember { name: Some("w"), ... }, ...], span: 16 }`), written with its
/// member names: `struct { w, ... }`.
fn unnamed_structs(msg: &str) -> String {
    const OPEN: &str = "Struct { members: [";
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(i) = rest.find(OPEN) {
        out.push_str(&rest[..i]);
        let body = &rest[i..];
        // the `}` that closes `Struct {`
        let mut depth = 0usize;
        let mut end = body.len();
        for (k, c) in body.char_indices() {
            match c {
                '{' | '[' | '(' => depth += 1,
                '}' | ']' | ')' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        let form = &body[..end];
        let names: Vec<&str> = form
            .split("name: Some(\"")
            .skip(1)
            .filter_map(|p| p.split_once("\")").map(|(n, _)| n))
            .collect();
        if names.is_empty() {
            out.push_str("struct");
        } else {
            out.push_str(&format!("struct {{ {} }}", names.join(", ")));
        }
        rest = &body[end..];
    }
    out.push_str(rest);
    out
}

/// naga's messages with its `Debug` type forms (`Vector { size: Tri, scalar: ... }`)
/// written as WGSL (`vec3<f32>`), `[N] (of type T)` as `` `T` ``, `Function [N]
/// 'f'` as ``function `f` ``, its operator names as the operators (``operator `&`
/// can't work with``) and a struct no module names by its members (`struct { w }`;
/// [`sanitize_in`] gives its name).
pub fn sanitize(msg: &str) -> String {
    let mut s = msg.to_string();
    for (debug, wgsl) in debug_type_forms() {
        if s.contains(debug.as_str()) {
            s = s.replace(debug.as_str(), wgsl);
        }
    }
    let s = unnamed_structs(&operator_names(&s));
    function_names(indexed_types(&s))
}

/// naga's `Debug` forms of the scalar, vector, matrix and value-pointer types,
/// each with its WGSL form, longest first (made once).
fn debug_type_forms() -> &'static [(String, String)] {
    use std::sync::OnceLock;
    static PAIRS: OnceLock<Vec<(String, String)>> = OnceLock::new();
    PAIRS.get_or_init(|| {
        let arena = naga::UniqueArena::<naga::Type>::new();
        let wgsl = |inner: &TypeInner| {
            let mut s = String::new();
            let _ = arena.write_type_inner(inner, &mut s);
            s
        };
        let scalars = [
            naga::Scalar::F16,
            naga::Scalar::F32,
            naga::Scalar::F64,
            naga::Scalar::I32,
            naga::Scalar::U32,
            naga::Scalar::I64,
            naga::Scalar::U64,
            naga::Scalar::BOOL,
            naga::Scalar::ABSTRACT_INT,
            naga::Scalar::ABSTRACT_FLOAT,
        ];
        let sizes = [
            naga::VectorSize::Bi,
            naga::VectorSize::Tri,
            naga::VectorSize::Quad,
        ];
        let mut v = Vec::new();
        for s in scalars {
            for size in sizes {
                let t = TypeInner::Vector { size, scalar: s };
                v.push((format!("{t:?}"), wgsl(&t)));
                if s.kind == ScalarKind::Float || s.kind == ScalarKind::AbstractFloat {
                    for rows in sizes {
                        let t = TypeInner::Matrix {
                            columns: size,
                            rows,
                            scalar: s,
                        };
                        v.push((format!("{t:?}"), wgsl(&t)));
                    }
                }
            }
            let t = TypeInner::Scalar(s);
            v.push((format!("{t:?}"), wgsl(&t)));
            v.push((format!("{s:?}"), wgsl(&t)));
            // pointers to a vector's component or to a vector (`&v.x`)
            for space in ADDRESS_SPACES {
                for size in [None].into_iter().chain(sizes.map(Some)) {
                    let t = TypeInner::ValuePointer {
                        size,
                        scalar: s,
                        space,
                    };
                    v.push((format!("{t:?}"), wgsl(&t)));
                }
            }
        }
        v.sort_by_key(|(d, _)| std::cmp::Reverse(d.len()));
        v
    })
}

/// `[3] (of type vec3<f32>)` → `` `vec3<f32>` ``
fn indexed_types(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('[') {
        let after = &rest[i + 1..];
        let digits = after.chars().take_while(|c| c.is_ascii_digit()).count();
        let tail = &after[digits..];
        if digits > 0 {
            if let Some(t) = tail.strip_prefix("] (of type ") {
                if let Some(close) = t.find(')') {
                    out.push_str(&rest[..i]);
                    out.push('`');
                    out.push_str(&t[..close]);
                    out.push('`');
                    rest = &t[close + 1..];
                    continue;
                }
            }
        }
        out.push_str(&rest[..=i]);
        rest = after;
    }
    out.push_str(rest);
    out
}

/// `Function [0] 'f' is invalid` → ``function `f` is invalid``
fn function_names(out: String) -> String {
    if let Some(r) = out.strip_prefix("Function [") {
        if let Some(q) = r.find("] '") {
            let r2 = &r[q + 3..];
            if let Some(e) = r2.find('\'') {
                return format!("function `{}`{}", &r2[..e], &r2[e + 1..]);
            }
        }
    }
    out
}

/// naga's `Expression [N] is invalid`.
fn is_expression_invalid(c: &str) -> bool {
    c.strip_prefix("Expression [")
        .and_then(|r| r.strip_suffix("] is invalid"))
        .is_some_and(|n| n.chars().all(|ch| ch.is_ascii_digit()))
}

/// A naga validation error as one diagnostic in WGSL terms: the innermost cause
/// (the most specific) as the message, at the last span; the other spans
/// labelled with the outermost cause. naga's `Expression [N] is invalid` and its
/// arena labels say nothing to a user and are dropped. `map` turns naga spans
/// (offsets in `wgsl`, the text `module` was parsed from) into source spans
/// (`None`: outside the user's text). An error naga gives no span (an entry
/// point's, or a function's implicit `return` at its end) points at the function's
/// `fn NAME`; `fallback` is used when nothing maps.
pub fn validation_diagnostic(
    e: &naga::WithSpan<naga::valid::ValidationError>,
    module: &naga::Module,
    wgsl: &str,
    map: impl Fn(naga::Span) -> Option<crate::script::Span>,
    fallback: crate::script::Span,
) -> crate::script::Diagnostic {
    let mut causes = vec![e.as_inner().to_string()];
    let mut src: &dyn std::error::Error = e.as_inner();
    while let Some(next) = src.source() {
        causes.push(next.to_string());
        src = next;
    }
    causes.retain(|c| !is_expression_invalid(c));
    let (function, return_problem) = function_of(e.as_inner(), module);
    let main = return_problem.unwrap_or_else(|| {
        sanitize_in(
            causes.last().map(String::as_str).unwrap_or("invalid"),
            module,
        )
    });
    let mut d = crate::script::Diagnostic::error(format!("WGSL validation: {main}"));
    let mut spans: Vec<crate::script::Span> = e.spans().filter_map(|(s, _)| map(*s)).collect();
    if spans.is_empty() {
        if let Some(r) = function.and_then(|f| fn_header(wgsl, f)) {
            spans.extend(map(naga::Span::new(r.start as u32, r.end as u32)));
        }
    }
    match spans.split_last() {
        Some((last, rest)) => {
            d = d.at(*last, "");
            let context = causes
                .first()
                .filter(|_| causes.len() > 1)
                .map(|c| sanitize_in(c, module))
                .unwrap_or_default();
            for s in rest {
                if s != last {
                    d = d.also(*s, context.clone());
                }
            }
        }
        None => d = d.at(fallback, ""),
    }
    d
}

/// The function (or entry point) a validation error is in, and, for a `return`
/// that does not match the declared type, that problem in words (naga writes
/// `The return expression None does not match the declared return type Some([4])`).
fn function_of<'a>(
    e: &'a naga::valid::ValidationError,
    module: &naga::Module,
) -> (Option<&'a str>, Option<String>) {
    use naga::common::wgsl::TypeContext as _;
    use naga::valid::{EntryPointError, FunctionError, ValidationError};
    let (name, f) = match e {
        ValidationError::Function { name, source, .. } => (name.as_str(), Some(source)),
        ValidationError::EntryPoint { name, source, .. } => (
            name.as_str(),
            match source {
                EntryPointError::Function(f) => Some(f),
                _ => None,
            },
        ),
        _ => return (None, None),
    };
    let problem = match f {
        Some(FunctionError::InvalidReturnType {
            expression,
            expected_ty,
        }) => {
            let ty =
                |h: &naga::Handle<naga::Type>| format!("`{}`", module.types.type_to_string(*h));
            Some(match (expression, expected_ty) {
                (None, Some(t)) => format!(
                    "`{name}` must return a {} value, but it can end (or `return`) without one",
                    ty(t)
                ),
                (Some(_), None) => {
                    format!("`{name}` declares no return type, but this `return` has a value")
                }
                (_, Some(t)) => format!(
                    "this `return` value is not of `{name}`'s declared return type {}",
                    ty(t)
                ),
                (None, None) => "invalid `return`".to_string(),
            })
        }
        _ => None,
    };
    (Some(name), problem)
}

/// The byte range of `fn NAME` in WGSL text (outside `//` comments), if present.
pub fn fn_header(wgsl: &str, name: &str) -> Option<std::ops::Range<usize>> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    for (offset, line) in crate::shader::preprocess::lines_with_offsets(wgsl) {
        let code = line.split("//").next().unwrap_or("");
        let mut from = 0;
        while let Some(i) = code[from..].find("fn") {
            let at = from + i;
            from = at + 2;
            if code[..at].chars().next_back().is_some_and(ident) {
                continue;
            }
            let rest = &code[at + 2..];
            let name_at = rest.len() - rest.trim_start().len();
            if name_at == 0 {
                continue;
            }
            let after = &rest[name_at..];
            if after.starts_with(name) && !after[name.len()..].starts_with(ident) {
                let end = at + 2 + name_at + name.len();
                return Some(offset + at..offset + end);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{FileId, Span};

    /// naga's validation error of `src` as the one diagnostic's message.
    fn validation_message(src: &str) -> String {
        let module = naga::front::wgsl::parse_str(src).expect("parses");
        let e = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .expect_err("a validation error");
        let file = FileId(0);
        let d = validation_diagnostic(
            &e,
            &module,
            src,
            |s| s.to_range().map(|r| Span::new(file, r.start, r.end)),
            Span::new(file, 0, 0),
        );
        d.message
    }

    /// The case (issue 29): `&` between an `i32` and a struct named the
    /// struct by naga's dump (`Struct { members: [StructMember { ...`).
    #[test]
    fn a_struct_in_a_type_error_is_named_by_its_wgsl_name() {
        let src = "struct Pencil { w: f32, strength: vec2<f32> }\n\
                   @group(0) @binding(0) var<uniform> pencil: Pencil;\n\
                   @fragment fn fs_main() -> @location(0) vec4<f32> {\n\
                   let i: i32 = 3;\n\
                   let p = pencil;\n\
                   let k = i & p;\n\
                   return vec4<f32>(f32(k));\n}\n";
        let m = validation_message(src);
        assert_eq!(
            m,
            "WGSL validation: operator `&` can't work with `i32` and `Pencil`"
        );
    }

    #[test]
    fn arrays_and_pointers_are_written_as_wgsl() {
        let src = "fn f() -> f32 {\n\
                   var a: array<vec2<f32>, 4>;\n\
                   let x: f32 = 1.0;\n\
                   return x + a;\n}\n";
        let m = validation_message(src);
        assert!(!m.contains('{') && !m.contains("Array"), "{m}");
        assert!(m.contains("`array<vec2<f32>, 4>`"), "{m}");
    }

    #[test]
    fn operator_names_and_struct_dumps_without_a_module() {
        assert_eq!(
            sanitize("Operation And can't work with [1] (of type Scalar(Scalar { kind: Sint, width: 4 })) and [3] (of type Struct { members: [StructMember { name: Some(\"w\"), ty: [0], binding: None, offset: 0 }, StructMember { name: Some(\"h\"), ty: [0], binding: None, offset: 4 }], span: 8 })"),
            "operator `&` can't work with `i32` and `struct { w, h }`"
        );
        assert_eq!(
            sanitize("ValuePointer { size: None, scalar: Scalar { kind: Float, width: 4 }, space: Function }"),
            "ptr<function, f32>"
        );
        // only naga's operator phrase is rewritten
        assert_eq!(sanitize("Operation And ok"), "Operation And ok");
        assert_eq!(sanitize("Struct { members: [x"), "struct");
    }
}
