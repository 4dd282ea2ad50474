//! GLSL built-ins that naga cannot carry to WGSL inside librashader, written
//! out in plain GLSL before glslang runs. A stage that names one gets small
//! GLSL functions after its `#version` line and a `#define` that redirects the
//! name to them; a `#line 2` after them keeps glslang's line numbers those of
//! the file.
//! - `packHalf2x16`/`unpackHalf2x16`: naga's translation needs its
//!   `SHADER_FLOAT16_IN_FLOAT32` capability, which librashader's validation does
//!   not grant, so FSR (`ffx_a.h` packs its RCAS constants with them) failed
//!   with the "float16" class. Replaced by 32-bit integer arithmetic (IEEE
//!   binary16, round to nearest even, infinities and NaN kept).
//! - `modf` with its `out` whole part: naga's SPIR-V reader leaves the result
//!   struct's special type unregistered ("special type not registered",
//!   `crt-1tap`). Replaced by `trunc` and a subtraction, for float and vectors.

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

/// Each replaced built-in: a name that selects it, and its GLSL.
const REPLACED: &[(&str, &str)] = &[("packHalf2x16", HALF_PACKING), ("modf", MODF)];

/// `stage` with the built-ins it names replaced (unchanged when it names none
/// or has no `#version` first line).
pub fn with_replaced_builtins(stage: String) -> String {
    let prelude: String = REPLACED
        .iter()
        .filter(|(name, _)| names(&stage, name))
        .map(|(_, glsl)| *glsl)
        .collect();
    if prelude.is_empty() {
        return stage;
    }
    let Some((first, rest)) = stage.split_once('\n') else {
        return stage;
    };
    if !first.trim_start().starts_with("#version") {
        return stage;
    }
    format!("{first}\n{prelude}#line 2\n{rest}")
}

/// Whether `text` has `name` as a whole identifier (`unpackHalf2x16` names
/// `packHalf2x16`'s group too).
fn names(text: &str, name: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices(name).any(|(at, _)| {
        let after = text[at + name.len()..].chars().next();
        let before = text[..at].chars().last();
        after.is_none_or(|c| !ident(c))
            && before.is_none_or(|c| !ident(c) || text[..at].ends_with("un"))
    })
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

    #[test]
    fn stages_without_half_packing_are_unchanged() {
        let s = "#version 450\nvoid main() {}\n".to_string();
        assert_eq!(with_replaced_builtins(s.clone()), s);
    }
}
