//! The EFFECT language: grammar ([`parse`]), typed AST and checks ([`ast`], and
//! [`material`] for `MATERIAL.name = { ... }` definitions), shared value types
//! ([`types`]), sub-pixel jitter sequences ([`jitter`]) and diagnostics ([`diag`]). No GPU code here.

pub mod ast;
pub mod diag;
pub mod jitter;
pub mod material;
pub mod parse;
pub mod types;

pub use ast::Module;
pub use diag::{Diagnostic, Diagnostics, FileId, Severity, SourceMap, Span, Spanned};
pub use jitter::{halton23, JitterPattern};
pub use material::{AlphaSpec, MaterialDef, MaterialSetting, MaterialShader, MaterialValue};

/// Parse and check one source text already added to `sources`: its effects,
/// materials and includes, every mistake reported to `diags` with its span.
pub fn parse_module(sources: &SourceMap, file: FileId, diags: &mut Diagnostics) -> Module {
    let text = sources.get(file).text.clone();
    let items = parse::parse(file, &text, diags);
    ast::check(file, &items, diags)
}
