//! Typed AST of the EFFECT language, built from the generic tree by a checker that
//! collects every mistake (unknown attribute, wrong value type, duplicate name, ...)
//! with its span. Cross-effect checks (unknown effect, cycles, sizes) are done when
//! lowering to the graph.
//!
//! This file holds the AST types; the checker is in `check` (files, effects,
//! references), `pass` (PASS entries), `param` (PARAM declarations and argument
//! conversion) and `suggest` ("did you mean").

use super::diag::{FileId, Span, Spanned};
use super::jitter::JitterPattern;
use super::material::MaterialDef;
use super::parse::Key;
use super::types::*;

/// One parsed and checked `.fx` file.
#[derive(Debug, Clone, Default)]
pub struct Module {
    pub file: FileId,
    pub includes: Vec<Spanned<String>>,
    pub effects: Vec<EffectDef>,
    /// `MATERIAL.name = { ... }` definitions, in file order (see [`material`]).
    pub materials: Vec<MaterialDef>,
}

#[derive(Debug, Clone)]
pub struct EffectDef {
    pub name: Spanned<String>,
    pub description: Option<String>,
    pub params: Vec<ParamDecl>,
    pub passes: Vec<PassDef>,
    pub out: Option<OutRef>,
    /// Default output format for this effect's passes.
    pub format: Option<Spanned<FormatSpec>>,
    /// Default working colour space for this effect's passes.
    pub colorspace: Option<Spanned<ColorSpace>>,
    /// `JITTER = halton23`: the effect wants its input frames rendered with this
    /// sub-pixel jitter sequence (temporal anti-aliasing).
    pub jitter: Option<Spanned<JitterPattern>>,
    pub span: Span,
}

impl EffectDef {
    pub fn pass(&self, name: &str) -> Option<&PassDef> {
        self.passes.iter().find(|p| p.name.node == name)
    }
    pub fn param(&self, name: &str) -> Option<&ParamDecl> {
        self.params.iter().find(|p| p.name.node == name)
    }
}

/// `OUT = final`, `OUT = PASS.final` or `OUT = IN`.
#[derive(Debug, Clone, PartialEq)]
pub enum OutRef {
    In(Span),
    Pass(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct ParamDecl {
    pub name: Spanned<String>,
    pub ty: ParamType,
    pub default: Value,
    pub range: Option<(f64, f64)>,
    /// `STEP`: the increment a control moves the value by (a slider's notch).
    pub step: Option<f64>,
    pub description: String,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub enum PassKind {
    /// `SHADER.name`: a WGSL fragment shader.
    Shader(Spanned<String>),
    /// `EFFECT.name`: another effect instantiated as a node.
    Effect(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct PassDef {
    pub name: Spanned<String>,
    pub kind: PassKind,
    pub inputs: Vec<InputDef>,
    pub params: Vec<ParamSet>,
    pub defines: Vec<DefineSet>,
    pub out: OutSpec,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct InputDef {
    pub name: Spanned<String>,
    pub source: Spanned<Source>,
    pub filter: Option<Spanned<Filter>>,
    pub wrap: Option<Spanned<(Wrap, Wrap)>>,
    /// The colour space the shader expects this input in (default: the pass's).
    pub colorspace: Option<Spanned<ColorSpace>>,
    /// `NAME.MIPMAP = true`: read with a generated mip chain.
    pub mipmap: Option<Spanned<bool>>,
}

impl InputDef {
    pub fn sampling(&self) -> Sampling {
        let (wrap_u, wrap_v) = self.wrap.as_ref().map(|w| w.node).unwrap_or_default();
        Sampling {
            filter: self.filter.as_ref().map(|f| f.node).unwrap_or_default(),
            wrap_u,
            wrap_v,
            mipmap: self.mipmap.as_ref().is_some_and(|m| m.node),
        }
    }
}

/// Where an input comes from. `frame` is 0 for the current frame, negative for
/// earlier frames, positive for later frames (input only).
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    In { frame: i32 },
    Pass { name: Spanned<String>, frame: i32 },
    Aux { name: Spanned<String> },
}

#[derive(Debug, Clone)]
pub struct ParamSet {
    pub name: Spanned<String>,
    pub value: Spanned<ParamArg>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum ParamArg {
    /// Numbers (a bool is written `true`/`false` and stored as 1/0).
    Literal { value: Value, is_bool: bool },
    /// A bare word: an enum choice of the receiving parameter.
    Word(String),
    /// `PARAM.name`: the enclosing effect's parameter.
    Param(Spanned<String>),
}

#[derive(Debug, Clone)]
pub struct DefineSet {
    pub name: Spanned<String>,
    pub value: Spanned<DefineArg>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum DefineArg {
    Int(i64),
    Param(Spanned<String>),
}

/// The name `OUT.RELATIVE_TO` gives the run's output size: the input's, or
/// the one the run asks for (`fxrun --size` on images; a slang preset's viewport).
pub const VIEWPORT: &str = "VIEWPORT";

#[derive(Debug, Clone, Default)]
pub struct OutSpec {
    pub size: Option<Spanned<(u32, u32)>>,
    /// `OUT.WIDTH` / `OUT.HEIGHT`: one axis in pixels, the other scaled.
    pub width: Option<Spanned<u32>>,
    pub height: Option<Spanned<u32>>,
    pub scale: Option<Spanned<(f64, f64)>>,
    /// `OUT.RELATIVE_TO`: the images the width and the height scale, each an
    /// input of the pass or `IN` (the effect's input); one name gives both.
    pub relative_to: Option<Spanned<(String, String)>>,
    pub format: Option<Spanned<FormatSpec>>,
    pub colorspace: Option<Spanned<ColorSpace>>,
}

/// `OUT.FORMAT = rgba16f` or `OUT.FORMAT = IN` (the effect input's format).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FormatSpec {
    Fixed(Format),
    SameAsInput,
}

/// Largest absolute frame offset accepted in `IN[n]` / `PASS.x[-n]`.
pub const MAX_FRAME_OFFSET: i32 = 16;
/// Largest texture side accepted.
pub const MAX_SIDE: u32 = 16384;

const FORMAT_LIST: &str =
    "rgba8, rgba8-srgb, rgba16f, rgba32f, rgb10a2, r8, r16f, r32f, rg16f, rg32f";

mod check;
mod param;
mod pass;
mod suggest;
mod unique;

pub use check::check;
use check::{colorspace_value, format_spec, numbers, pair};
pub(crate) use check::{type_error, word};
use param::check_param_decl;
pub use param::convert_arg;
use pass::{check_pass, classify_binding, Binding};
pub use suggest::suggest;
pub(crate) use unique::{is_new_name, key_name, SeenKeys};

impl Key {
    /// Helper used in tests.
    pub fn span_text<'a>(&self, text: &'a str) -> &'a str {
        &text[self.span.start as usize..self.span.end as usize]
    }
}
