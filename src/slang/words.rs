//! Whole GLSL/WGSL identifiers found and replaced in text: the rewrites that run
//! on source text (before glslang, or on the written WGSL) use these, so an
//! identifier inside a longer one (`main` in `mainly`) is never touched.

fn ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// `text` with every whole identifier `from` replaced by `to`.
pub fn replace_word(text: &str, from: &str, to: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(from) {
        let before = rest[..at].chars().next_back();
        let after = rest[at + from.len()..].chars().next();
        out.push_str(&rest[..at]);
        if before.is_some_and(ident) || after.is_some_and(ident) {
            out.push_str(from);
        } else {
            out.push_str(to);
        }
        rest = &rest[at + from.len()..];
    }
    out.push_str(rest);
    out
}

/// Whether `text` has `word` as a whole identifier.
pub fn has_word(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        !before.is_some_and(ident) && !after.is_some_and(ident)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_whole_identifiers_are_found_and_replaced() {
        assert_eq!(
            replace_word(
                "void mainly() {}\nvoid  main (){}\nvoidmain()",
                "main",
                "fx_main"
            ),
            "void mainly() {}\nvoid  fx_main (){}\nvoidmain()"
        );
        assert!(has_word("x = unpackHalf2x16(p);", "unpackHalf2x16"));
        assert!(!has_word("x = unpackHalf2x16(p);", "packHalf2x16"));
        assert!(!has_word("float modfoo;", "modf"));
    }
}
