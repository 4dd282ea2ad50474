//! Prefixing the module-scope names of a WGSL text, so several lighting shaders
//! (each with its `fn lighting` and `struct LightingParams`) fit in one module as
//! `lm0_lighting`, `lm1_lighting`, ...
//!
//! The text is tokenized (comments and `#` directive lines are skipped), the names
//! declared at module scope are collected (`fn`, `struct`, `const`, `override`,
//! `var`, `alias`), and every identifier token with one of those names is
//! renamed, except member accesses (after `.`), struct member declarations and
//! attribute names. Renaming a local that happens to share a module-scope name is
//! harmless: its declaration and uses are renamed alike.

/// A token of interest: an identifier (byte range) or one punctuation byte.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tok {
    Ident(usize, usize),
    Punct(u8),
}

fn is_ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_' || c >= 0x80
}

fn is_ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c >= 0x80
}

/// Identifiers and punctuation of `text`, outside comments and directive lines.
/// Numbers are skipped (`1e5`, `0x1fu` are not identifiers).
fn tokenize(text: &str) -> Result<Vec<Tok>, String> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let mut line_start = true;
    while i < b.len() {
        let c = b[i];
        if c == b'\n' {
            line_start = true;
            i += 1;
            continue;
        }
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if line_start && c == b'#' {
            // A preprocessor directive: skip the line.
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        line_start = false;
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if b[i..].starts_with(b"/*") {
            let mut depth = 1;
            i += 2;
            while depth > 0 {
                if i >= b.len() {
                    return Err("unterminated block comment".into());
                }
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                } else {
                    i += 1;
                }
            }
            continue;
        }
        if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            // A number literal, with its suffix, exponent and hex digits.
            let hex = b[i..].starts_with(b"0x") || b[i..].starts_with(b"0X");
            i += 1;
            while i < b.len()
                && (is_ident_char(b[i])
                    || b[i] == b'.'
                    || ((b[i] == b'+' || b[i] == b'-')
                        && if hex {
                            matches!(b[i - 1], b'p' | b'P')
                        } else {
                            matches!(b[i - 1], b'e' | b'E')
                        }))
            {
                i += 1;
            }
            continue;
        }
        if is_ident_start(c) {
            let s = i;
            while i < b.len() && is_ident_char(b[i]) {
                i += 1;
            }
            out.push(Tok::Ident(s, i));
            continue;
        }
        out.push(Tok::Punct(c));
        i += 1;
    }
    Ok(out)
}

/// Module-scope names declared in `text`, with the byte range of each declaring
/// identifier, in order.
pub fn module_declarations(text: &str) -> Result<Vec<(String, usize, usize)>, String> {
    let toks = tokenize(text)?;
    let mut out = Vec::new();
    let mut depth: i64 = 0; // `{`, `(`, `[` nesting
    let mut i = 0;
    while i < toks.len() {
        match toks[i] {
            Tok::Punct(b'{' | b'(' | b'[') => depth += 1,
            Tok::Punct(b'}' | b')' | b']') => depth -= 1,
            Tok::Ident(s, e) if depth == 0 => {
                let kw = &text[s..e];
                if matches!(kw, "fn" | "struct" | "const" | "override" | "var" | "alias") {
                    let mut j = i + 1;
                    if kw == "var" && toks.get(j) == Some(&Tok::Punct(b'<')) {
                        while j < toks.len() && toks[j] != Tok::Punct(b'>') {
                            j += 1;
                        }
                        j += 1;
                    }
                    if let Some(Tok::Ident(ns, ne)) = toks.get(j) {
                        out.push((text[*ns..*ne].to_string(), *ns, *ne));
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    if depth != 0 {
        return Err("unbalanced brackets".into());
    }
    Ok(out)
}

/// The byte ranges of the attributes `@name` (for `name` in `names`) in `text`,
/// outside comments, e.g. `@fragment`.
pub fn find_attributes(text: &str, names: &[&str]) -> Result<Vec<(String, usize, usize)>, String> {
    let toks = tokenize(text)?;
    let mut out = Vec::new();
    for w in toks.windows(2) {
        if let [Tok::Punct(b'@'), Tok::Ident(s, e)] = *w {
            if names.contains(&&text[s..e]) {
                out.push((text[s..e].to_string(), s - 1, e));
            }
        }
    }
    Ok(out)
}

/// Prefix every module-scope name defined in `wgsl` (except those in `keep`) with
/// `prefix`, in declarations and references alike.
pub fn prefix_module_names(wgsl: &str, prefix: &str, keep: &[&str]) -> Result<String, String> {
    let names: std::collections::HashSet<String> = module_declarations(wgsl)?
        .into_iter()
        .map(|(n, _, _)| n)
        .filter(|n| !keep.contains(&n.as_str()))
        .collect();
    let toks = tokenize(wgsl)?;
    let mut edits: Vec<usize> = Vec::new(); // start offsets of identifiers to prefix
                                            // Brackets: what each open `{` belongs to (a struct body or not).
    let mut braces: Vec<bool> = Vec::new();
    let mut struct_pending = false;
    // Inside `@builtin(...)`-style attribute arguments: (paren depth at entry).
    let mut attr_args: Option<usize> = None;
    let mut parens = 0usize;
    for (k, t) in toks.iter().enumerate() {
        let prev = k.checked_sub(1).map(|p| toks[p]);
        let next = toks.get(k + 1).copied();
        match *t {
            Tok::Punct(b'{') => {
                braces.push(struct_pending);
                struct_pending = false;
            }
            Tok::Punct(b'}') => {
                braces.pop();
            }
            Tok::Punct(b'(') => parens += 1,
            Tok::Punct(b')') => {
                parens = parens.saturating_sub(1);
                if attr_args == Some(parens) {
                    attr_args = None;
                }
            }
            Tok::Ident(s, e) => {
                let word = &wgsl[s..e];
                if word == "struct" && braces.is_empty() {
                    struct_pending = true;
                }
                if prev == Some(Tok::Punct(b'@')) {
                    // An attribute name; the arguments of these name built-ins, not
                    // module-scope things.
                    if matches!(word, "builtin" | "interpolate" | "diagnostic")
                        && next == Some(Tok::Punct(b'('))
                    {
                        attr_args = Some(parens);
                    }
                    continue;
                }
                if attr_args.is_some() || !names.contains(word) {
                    continue;
                }
                if prev == Some(Tok::Punct(b'.')) {
                    continue; // member access or swizzle
                }
                let in_struct_body = braces.last() == Some(&true);
                if in_struct_body && next == Some(Tok::Punct(b':')) {
                    continue; // a member declaration (possibly after attributes)
                }
                edits.push(s);
            }
            _ => {}
        }
    }
    let mut out = String::with_capacity(wgsl.len() + edits.len() * prefix.len());
    let mut last = 0;
    for s in edits {
        out.push_str(&wgsl[last..s]);
        out.push_str(prefix);
        last = s;
    }
    out.push_str(&wgsl[last..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renames_declarations_and_uses_only() {
        let src = "// fn lighting in a comment\nstruct LightingParams {\n    power: f32, // power\n    @align(16) scale: f32,\n}\nconst scale = 2.0e-1;\nfn helper(v: vec3<f32>) -> f32 { return v.x * scale; }\n/* helper */ fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput {\n    let power = params.power * helper(in.normal) * 1e5 * scale;\n    return LightingOutput(vec3<f32>(power), vec3<f32>(0.0));\n}\n";
        let out = prefix_module_names(src, "lm0_", &["LightingInput", "LightingOutput"]).unwrap();
        assert_eq!(
            out,
            "// fn lighting in a comment\nstruct lm0_LightingParams {\n    power: f32, // power\n    @align(16) scale: f32,\n}\nconst lm0_scale = 2.0e-1;\nfn lm0_helper(v: vec3<f32>) -> f32 { return v.x * lm0_scale; }\n/* helper */ fn lm0_lighting(in: LightingInput, params: lm0_LightingParams) -> LightingOutput {\n    let power = params.power * lm0_helper(in.normal) * 1e5 * lm0_scale;\n    return LightingOutput(vec3<f32>(power), vec3<f32>(0.0));\n}\n"
        );
        let decls: Vec<String> = module_declarations(src)
            .unwrap()
            .into_iter()
            .map(|d| d.0)
            .collect();
        assert_eq!(decls, ["LightingParams", "scale", "helper", "lighting"]);
    }

    #[test]
    fn vars_overrides_aliases() {
        let src = "@group(2) @binding(0) var<uniform> u: U;\nstruct U { a: f32 }\nalias V = vec3<f32>;\noverride k: f32 = 1.0;\nvar<private> p: V;\nfn f(@builtin(position) position: vec4<f32>) -> f32 { p = V(u.a * k); return position.x; }\n";
        let out = prefix_module_names(src, "x_", &[]).unwrap();
        assert_eq!(
            out,
            "@group(2) @binding(0) var<uniform> x_u: x_U;\nstruct x_U { a: f32 }\nalias x_V = vec3<f32>;\noverride x_k: f32 = 1.0;\nvar<private> x_p: x_V;\nfn x_f(@builtin(position) position: vec4<f32>) -> f32 { x_p = x_V(x_u.a * x_k); return position.x; }\n"
        );
        assert!(prefix_module_names("/* open", "x_", &[]).is_err());
    }
}
