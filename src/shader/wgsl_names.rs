//! naga's messages in WGSL terms: its `Debug` type forms written as WGSL type names.

use naga::common::wgsl::TypeContext as _;
use naga::{ScalarKind, TypeInner};

/// naga's messages with its `Debug` type forms (`Vector { size: Tri, scalar: ... }`)
/// written as WGSL (`vec3<f32>`), `[N] (of type T)` as `` `T` `` and
/// `Function [N] 'f'` as ``function `f` ``.
pub fn sanitize(msg: &str) -> String {
    use std::sync::OnceLock;
    static PAIRS: OnceLock<Vec<(String, String)>> = OnceLock::new();
    let pairs = PAIRS.get_or_init(|| {
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
        }
        v.sort_by_key(|(d, _)| std::cmp::Reverse(d.len()));
        v
    });
    let mut s = msg.to_string();
    for (debug, wgsl) in pairs {
        if s.contains(debug.as_str()) {
            s = s.replace(debug.as_str(), wgsl);
        }
    }
    // `[3] (of type vec3<f32>)` → `` `vec3<f32>` ``
    let mut out = String::with_capacity(s.len());
    let mut rest = s.as_str();
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
    // `Function [0] 'f' is invalid` → ``function `f` is invalid``
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
