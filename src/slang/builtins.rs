//! GLSL built-ins that naga cannot carry to WGSL inside librashader, written
//! out in plain GLSL before glslang runs. A stage that names one gets small
//! GLSL functions after librashader's header and a `#define` that redirects the
//! name to them; the header's `#line` marker, repeated after them, keeps
//! glslang's line numbers those of the file.
//! - `packHalf2x16`/`unpackHalf2x16`: naga's translation needs its
//!   `SHADER_FLOAT16_IN_FLOAT32` capability, which librashader's validation does
//!   not grant, so FSR (`ffx_a.h` packs its RCAS constants with them) failed
//!   with the "float16" class. Replaced by 32-bit integer arithmetic (IEEE
//!   binary16, round to nearest even, infinities and NaN kept).
//! - `modf` with its `out` whole part: naga's SPIR-V reader leaves the result
//!   struct's special type unregistered ("special type not registered",
//!   `crt-1tap`). Replaced by `trunc` and a subtraction, for float and vectors.

use super::words::has_word;

/// The half-float packing functions (one line each) and the redirections.
const HALF_PACKING: &str = "\
uint fx_f32_to_f16(float v) { uint x = floatBitsToUint(v); uint s = (x >> 16) & 0x8000u; uint ex = (x >> 23) & 0xffu; uint m = x & 0x7fffffu; int e = int(ex) - 112; if (ex == 0xffu) { return s | 0x7c00u | (m != 0u ? 0x200u : 0u); } if (e >= 31) { return s | 0x7c00u; } if (e <= 0) { if (e < -10) { return s; } m |= 0x800000u; uint sh = uint(14 - e); uint h = m >> sh; uint rem = m & ((1u << sh) - 1u); uint mid = 1u << (sh - 1u); if (rem > mid || (rem == mid && (h & 1u) != 0u)) { h += 1u; } return s | h; } uint h = (uint(e) << 10) | (m >> 13); uint rem = m & 0x1fffu; if (rem > 0x1000u || (rem == 0x1000u && (h & 1u) != 0u)) { h += 1u; } return s | h; }
float fx_f16_to_f32(uint h) { uint s = (h & 0x8000u) << 16; uint e = (h >> 10) & 0x1fu; uint m = h & 0x3ffu; if (e == 0u) { return uintBitsToFloat(s) + (s != 0u ? -1.0 : 1.0) * float(m) * exp2(-24.0); } if (e == 31u) { return uintBitsToFloat(s | 0x7f800000u | (m << 13)); } return uintBitsToFloat(s | ((e + 112u) << 23) | (m << 13)); }
uint fx_packHalf2x16(vec2 v) { return fx_f32_to_f16(v.x) | (fx_f32_to_f16(v.y) << 16); }
vec2 fx_unpackHalf2x16(uint p) { return vec2(fx_f16_to_f32(p & 0xffffu), fx_f16_to_f32(p >> 16)); }
#define packHalf2x16 fx_packHalf2x16
#define unpackHalf2x16 fx_unpackHalf2x16
";

/// `modf` for float and vectors, and the redirection.
const MODF: &str = "\
float fx_modf(float x, out float i) { i = trunc(x); return x - i; }
vec2 fx_modf(vec2 x, out vec2 i) { i = trunc(x); return x - i; }
vec3 fx_modf(vec3 x, out vec3 i) { i = trunc(x); return x - i; }
vec4 fx_modf(vec4 x, out vec4 i) { i = trunc(x); return x - i; }
#define modf fx_modf
";

/// Each group of replaced built-ins: the names that select it, and its GLSL.
const REPLACED: &[(&[&str], &str)] = &[
    (&["packHalf2x16", "unpackHalf2x16"], HALF_PACKING),
    (&["modf"], MODF),
];

/// `stage` with the built-ins it names replaced (unchanged when it names none).
/// The functions go after librashader's header (`#version`, its `#extension` and
/// `#define` lines, up to its first `#line` marker), so that extensions still
/// come before any code, and that marker is repeated after them.
pub fn with_replaced_builtins(stage: String) -> String {
    let prelude: String = REPLACED
        .iter()
        .filter(|(names, _)| names.iter().any(|n| has_word(&stage, n)))
        .map(|(_, glsl)| *glsl)
        .collect();
    if prelude.is_empty() {
        return stage;
    }
    // The end of librashader's first `#line` marker, and the marker.
    let mut end = 0;
    let marker = stage.split_inclusive('\n').find(|line| {
        end += line.len();
        line.starts_with("#line ")
    });
    match marker {
        Some(marker) => format!("{}{prelude}{marker}{}", &stage[..end], &stage[end..]),
        // No marker (librashader's line directives off): after `#version`.
        None => match stage.split_once('\n') {
            Some((first, rest)) if first.trim_start().starts_with("#version") => {
                format!("{first}\n{prelude}#line 2\n{rest}")
            }
            _ => stage,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prelude_follows_the_version_line_and_restores_line_two() {
        let s = with_replaced_builtins("#version 450\nuint x = packHalf2x16(vec2(1.0));\n".into());
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines[0], "#version 450");
        assert!(lines.contains(&"#define packHalf2x16 fx_packHalf2x16"));
        let at = lines.iter().position(|l| *l == "#line 2").unwrap();
        assert_eq!(lines[at + 1], "uint x = packHalf2x16(vec2(1.0));");
    }

    #[test]
    fn modf_is_redirected_and_a_longer_name_is_not_a_use() {
        let s = with_replaced_builtins("#version 450\nfloat a = modf(1.5, b);\n".into());
        assert!(s.contains("#define modf fx_modf\n#line 2\nfloat a = modf(1.5, b);"));
        let t = "#version 450\nfloat modfoo;\n".to_string();
        assert_eq!(with_replaced_builtins(t.clone()), t);
    }

    /// librashader's header: the functions after its `#line` marker (extensions
    /// stay before any code), the marker repeated after them.
    #[test]
    fn the_prelude_follows_librashaders_header() {
        let s = with_replaced_builtins(
            "#version 450\n#extension GL_GOOGLE_cpp_style_line_directive : require\n#line 2 \"a.slang\"\nfloat a = modf(1.5, b);\n"
                .into(),
        );
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(
            lines[1],
            "#extension GL_GOOGLE_cpp_style_line_directive : require"
        );
        assert_eq!(lines[2], "#line 2 \"a.slang\"");
        assert!(lines[3].starts_with("float fx_modf("));
        assert_eq!(
            &lines[lines.len() - 2..],
            &["#line 2 \"a.slang\"", "float a = modf(1.5, b);"]
        );
    }

    #[test]
    fn stages_without_half_packing_are_unchanged() {
        let s = "#version 450\nvoid main() {}\n".to_string();
        assert_eq!(with_replaced_builtins(s.clone()), s);
    }
}
