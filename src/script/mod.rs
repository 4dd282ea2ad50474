//! The EFFECT language: grammar ([`parse`]), typed AST and checks ([`ast`]),
//! shared value types ([`types`]) and diagnostics ([`diag`]). No GPU code here.

pub mod ast;
pub mod diag;
pub mod parse;
pub mod types;

pub use ast::Module;
pub use diag::{Diagnostic, Diagnostics, FileId, Severity, SourceMap, Span, Spanned};

/// Parse and check one source text already added to `sources`.
pub fn parse_module(sources: &SourceMap, file: FileId, diags: &mut Diagnostics) -> Module {
    let text = sources.get(file).text.clone();
    let items = parse::parse(file, &text, diags);
    ast::check(file, &items, diags)
}
