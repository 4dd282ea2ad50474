//! Names and keys given once, as effects, passes, parameters and materials check
//! them: the name a statement's key gives, a name not defined before, an attribute
//! not set before in its block.

use crate::script::diag::{Diagnostic, Diagnostics, Span, Spanned};
use crate::script::parse::Stmt;

/// The name a statement's key gives: its last word when the key has `words` words;
/// else `None` and the error "`rule`, found `KEY`" (`expected` at the key).
pub(crate) fn key_name(
    stmt: &Stmt,
    words: usize,
    rule: &str,
    expected: &str,
    diags: &mut Diagnostics,
) -> Option<Spanned<String>> {
    if stmt.key.parts.len() != words {
        diags.push(
            Diagnostic::error(format!("{rule}, found `{}`", stmt.key.dotted()))
                .at(stmt.key.span, expected),
        );
        return None;
    }
    stmt.key.parts.last().cloned()
}

/// Whether `name` is new among the names `defined` before it; one defined before
/// is an error ("`what` `NAME` is `verb` twice", both places shown).
pub(crate) fn is_new_name<'a>(
    defined: impl IntoIterator<Item = &'a Spanned<String>>,
    name: &Spanned<String>,
    what: &str,
    verb: &str,
    diags: &mut Diagnostics,
) -> bool {
    let Some(prev) = defined.into_iter().find(|n| n.node == name.node) else {
        return true;
    };
    diags.push(
        Diagnostic::error(format!("{what} `{}` is {verb} twice", name.node))
            .at(name.span, format!("{verb} again here"))
            .also(prev.span, format!("first {verb} here")),
    );
    false
}

/// The attribute keys a block (an effect, a pass, a material, a shader's settings)
/// has set so far.
pub(crate) struct SeenKeys {
    /// The block, for messages: "effect `blur`".
    within: String,
    keys: Vec<(String, Span)>,
}

impl SeenKeys {
    pub(crate) fn new(within: String) -> Self {
        SeenKeys {
            within,
            keys: Vec::new(),
        }
    }

    /// Whether the block has set `key`.
    pub(crate) fn contains(&self, key: &str) -> bool {
        self.keys.iter().any(|(k, _)| k == key)
    }

    /// Records `key` (at `span`); false, with the error "`KEY` is set twice in
    /// ...", when the block set it before.
    pub(crate) fn first(&mut self, key: &str, span: Span, diags: &mut Diagnostics) -> bool {
        if let Some((_, prev)) = self.keys.iter().find(|(k, _)| k == key) {
            diags.push(
                Diagnostic::error(format!("`{key}` is set twice in {}", self.within))
                    .at(span, "set again here")
                    .also(*prev, "first set here"),
            );
            return false;
        }
        self.keys.push((key.to_string(), span));
        true
    }
}
