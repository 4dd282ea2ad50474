//! Material shaders: finding, assembling (`#include`), checking and reflecting the
//! two small WGSL functions a material is made of.
//!
//! - A *surface shader* defines `fn surface(in: SurfaceInput) -> SurfaceOutput`,
//!   optionally `struct SurfaceParams { ... }` (fields annotated like effect
//!   parameters) bound once as `@group(2) @binding(N) var<uniform> NAME: SurfaceParams;`,
//!   textures `@group(2) @binding(N) var NAME: texture_2d<f32>; // [@srgb] text` and
//!   samplers `@group(2) @binding(N) var NAME: sampler;`. Bindings are in group 2
//!   and below 16 (16 and up are the engine's). It may test the feature flags
//!   `HAS_<TEXTURE>` and [`ENGINE_FLAGS`] with `#ifdef`/`#ifndef`
//!   (see [`super::features`]).
//! - A *lighting shader* defines `fn lighting(in: LightingInput) -> LightingOutput`
//!   or `fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput`
//!   with an annotated `struct LightingParams`. It declares no resources.
//!
//! Both see the engine's types ([`MATERIAL_INTERFACE`]); names starting with `fx_`
//! or `FX_` are the engine's. The engine generates the entry points.

use super::features::{self, convert_features, texture_flag, FeatureMode, ENGINE_FLAGS};
use super::include::{self, assemble, Assembly, IncludeFs, IncludeOrigin, LineMap, RealFs};
use super::preprocess::{preprocess, PreprocessError};
use super::reflect::{member_annotations, FieldType, UniformMember};
use super::rename::{find_attributes, module_declarations, prefix_module_names};
use super::ShaderFile;
use crate::graph::library::EMBEDDED_MATERIAL_SHADERS;
use crate::script::{Diagnostic, FileId, SourceMap, Span};
use naga::common::wgsl::TypeContext as _;
use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};
use std::path::Path;

/// The engine's types every material shader sees (appended to it).
pub const MATERIAL_INTERFACE: &str = include_str!("material_interface.wgsl");
/// How [`MATERIAL_INTERFACE`] is named in messages.
pub const MATERIAL_INTERFACE_SHOWN: &str = "<builtin>/material_interface.wgsl";
/// The names [`MATERIAL_INTERFACE`] declares (kept when renaming lighting shaders).
pub const INTERFACE_NAMES: &[&str] = &[
    "SurfaceInput",
    "SurfaceOutput",
    "LightingInput",
    "LightingOutput",
    "FX_PI",
];
/// The bind group of a surface shader's resources.
pub const MATERIAL_GROUP: u32 = 2;
/// Surface shader bindings are below this; the engine's start here.
pub const FIRST_ENGINE_BINDING: u32 = 16;
/// The declaration the feature test of [`FeatureMode::Branch`] reads in the checks
/// (`fx_features` bit `i` is the shader's `i`-th flag of [`MaterialShader::flags`]).
pub const BRANCH_FEATURES_DECL: &str =
    "@group(2) @binding(16) var<uniform> fx_features: vec4<u32>;\n";

/// The built-in material tree: `standard.wgsl`, `lib/brdf.wgsl`, ...
pub fn embedded_material_shader(rel: &str) -> Option<&'static str> {
    EMBEDDED_MATERIAL_SHADERS
        .iter()
        .find(|(n, _)| *n == rel)
        .map(|(_, t)| *t)
}

/// The built-in material shaders by name (`standard`, `phong`, ...), without the
/// library files.
pub fn builtin_material_shaders() -> Vec<&'static str> {
    EMBEDDED_MATERIAL_SHADERS
        .iter()
        .filter(|(n, _)| !n.contains('/'))
        .filter_map(|(n, _)| n.strip_suffix(".wgsl"))
        .collect()
}

const BUILTIN_PREFIX: &str = "<builtin>/shaders/materials/";

/// Find a material shader: `name` (`phong`, `phong.wgsl`, `sub/mine.wgsl`) under
/// `dir` first (confined like includes: no `..`, no absolute path, symlinks must
/// stay under `dir`, a regular file of at most 1 MiB), then the built-in ones.
pub fn find_material_shader(name: &str, dir: Option<&Path>) -> Option<ShaderFile> {
    let file = if name.ends_with(".wgsl") {
        name.to_string()
    } else {
        format!("{name}.wgsl")
    };
    let parts = include::check_relative(&file).ok()?;
    if let Some(dir) = dir {
        if let Ok(canon_dir) = std::fs::canonicalize(dir) {
            if let Ok(Some((canon, text))) = include::read_confined(&canon_dir, &parts, &RealFs) {
                return Some(ShaderFile {
                    shown: dir.join(&file).display().to_string(),
                    text,
                    path: Some(canon),
                });
            }
        }
    }
    let rel = parts.join("/");
    if rel.starts_with("lib/") {
        return None;
    }
    embedded_material_shader(&rel).map(|t| ShaderFile {
        shown: format!("{BUILTIN_PREFIX}{rel}"),
        text: t.to_string(),
        path: None,
    })
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MaterialShaderKind {
    Surface,
    Lighting,
}

impl MaterialShaderKind {
    fn function(self) -> &'static str {
        match self {
            MaterialShaderKind::Surface => "surface",
            MaterialShaderKind::Lighting => "lighting",
        }
    }
    fn params_struct(self) -> &'static str {
        match self {
            MaterialShaderKind::Surface => "SurfaceParams",
            MaterialShaderKind::Lighting => "LightingParams",
        }
    }
}

/// The `SurfaceParams` / `LightingParams` struct.
#[derive(Debug, Clone)]
pub struct MaterialParams {
    pub struct_name: String,
    /// Size in bytes (WGSL layout rules).
    pub size: u32,
    pub members: Vec<UniformMember>,
    /// The struct declaration.
    pub span: Span,
}

/// A `texture_2d<f32>` of a surface shader.
#[derive(Debug, Clone)]
pub struct MaterialTexture {
    pub name: String,
    pub binding: u32,
    /// `// @srgb`: colour data, sampled through an sRGB view.
    pub srgb: bool,
    /// Its feature flag, `HAS_<NAME>`.
    pub flag: String,
    pub description: String,
    pub span: Span,
}

/// A `sampler` of a surface shader (the engine binds a linear, repeat, mipmapped one).
#[derive(Debug, Clone)]
pub struct MaterialSampler {
    pub name: String,
    pub binding: u32,
    pub span: Span,
}

/// A checked material shader.
#[derive(Debug, Clone)]
pub struct MaterialShader {
    /// The name it was asked for (`standard`).
    pub name: String,
    pub kind: MaterialShaderKind,
    /// How its file is named in messages.
    pub label: String,
    /// Its file in the [`SourceMap`].
    pub file: FileId,
    /// The file with its includes appended (directives blanked), without the
    /// interface and not preprocessed; spans map back through `assembly`.
    pub text: String,
    pub assembly: Assembly,
    /// Surface: every flag a pipeline may set ([`ENGINE_FLAGS`], then `HAS_<TEXTURE>`
    /// per texture in binding order); bit `i` of [`FeatureMode::Branch`]'s
    /// feature word is `flags[i]`. Empty for lighting shaders.
    pub flags: Vec<String>,
    /// The flags the text tests (a subset of `flags`), sorted.
    pub features: Vec<String>,
    pub params: Option<MaterialParams>,
    /// Surface: the binding and variable name of the `SurfaceParams` uniform.
    pub params_binding: Option<u32>,
    pub params_var: Option<String>,
    pub textures: Vec<MaterialTexture>,
    pub samplers: Vec<MaterialSampler>,
    /// Lighting: `fn lighting(in: LightingInput, params: LightingParams)`.
    pub lighting_takes_params: bool,
}

impl MaterialShader {
    /// The surface shader's WGSL for one way of compiling its feature flags
    /// (without the interface, which the caller appends once per module):
    /// - `Preprocess`: the flags in `enabled` are defined;
    /// - `Override`: `override FLAG: bool = false;` for every flag of [`Self::flags`];
    /// - `Branch`: `branch_cond(flag)` is the run-time test of a flag.
    ///
    /// Lighting shaders have no flags: every mode gives the preprocessed text.
    pub fn wgsl(
        &self,
        mode: FeatureMode,
        enabled: &[&str],
        branch_cond: &dyn Fn(&str) -> String,
    ) -> Result<String, PreprocessError> {
        let flags: Vec<&str> = self.flags.iter().map(String::as_str).collect();
        let converted = match mode {
            FeatureMode::Preprocess => {
                let defs: Vec<(String, i64)> = enabled
                    .iter()
                    .filter(|f| flags.contains(f))
                    .map(|f| (f.to_string(), 1))
                    .collect();
                return preprocess(&self.text, &defs).map(|r| r.0);
            }
            FeatureMode::Override => features::to_override_mode(&self.text, &flags)?,
            FeatureMode::Branch => convert_features(&self.text, &flags, branch_cond)?,
        };
        preprocess(&converted, &[]).map(|r| r.0)
    }

    /// A lighting shader's WGSL with its module-scope names prefixed (`lm0_` gives
    /// `lm0_lighting`, `lm0_LightingParams`), to sit beside other lighting shaders
    /// and the interface in one module.
    pub fn lighting_wgsl(&self, prefix: &str) -> Result<String, String> {
        let (text, _) = preprocess(&self.text, &[]).map_err(|e| e.message)?;
        prefix_module_names(&text, prefix, INTERFACE_NAMES)
    }
}

/// Load and check a material shader from disk or the built-in library (includes
/// read through the real file system).
pub fn load_material_shader(
    kind: MaterialShaderKind,
    name: &str,
    file: ShaderFile,
    sources: &mut SourceMap,
) -> Result<MaterialShader, Vec<Diagnostic>> {
    load_material_shader_with(kind, name, file, &RealFs, sources)
}

/// [`load_material_shader`] with includes read through `fs`.
pub fn load_material_shader_with(
    kind: MaterialShaderKind,
    name: &str,
    file: ShaderFile,
    fs: &dyn IncludeFs,
    sources: &mut SourceMap,
) -> Result<MaterialShader, Vec<Diagnostic>> {
    let root = sources.add(file.shown.clone(), file.text.clone());
    let origin = match (&file.path, file.shown.strip_prefix(BUILTIN_PREFIX)) {
        (Some(p), _) => IncludeOrigin::Disk(p.clone()),
        (None, Some(rel)) => IncludeOrigin::Builtin(rel.to_string()),
        (None, None) => IncludeOrigin::Memory,
    };
    let asm = assemble(root, &file.shown, &file.text, origin, fs, sources)?;
    let mut ck = Checker {
        kind,
        asm: &asm,
        root,
        sources,
        diags: Vec::new(),
    };
    let out = ck.check(name, &file.shown);
    match out {
        Some(mut m) if ck.diags.is_empty() => {
            m.text = asm.text.clone();
            m.assembly = asm;
            Ok(m)
        }
        _ => Err(ck.diags),
    }
}

/// One way the checks compile the text.
struct Variant {
    /// What the variant is, for a note on its errors.
    what: String,
    /// The text derived line by line from the assembly (plus appended lines).
    derived: String,
    /// Appended after the interface.
    extra: &'static str,
}

struct Checker<'a> {
    kind: MaterialShaderKind,
    asm: &'a Assembly,
    root: FileId,
    sources: &'a mut SourceMap,
    diags: Vec<Diagnostic>,
}

/// A validated variant: the module, its full text, and how to map its spans.
struct Compiled {
    module: naga::Module,
    lines: LineMap,
    iface_start: usize,
    iface_end: usize,
    iface: FileId,
}

impl Checker<'_> {
    fn file_start(&self) -> Span {
        Span::new(self.root, 0, 0)
    }

    fn interface_file(&mut self) -> FileId {
        match self.sources.find(MATERIAL_INTERFACE_SHOWN) {
            Some(id) => id,
            None => self
                .sources
                .add(MATERIAL_INTERFACE_SHOWN, MATERIAL_INTERFACE),
        }
    }

    /// A span of the assembled text, in its file.
    fn asm_span(&self, start: usize, end: usize) -> Span {
        self.asm
            .map_span(start, end)
            .unwrap_or_else(|| self.file_start())
    }

    fn preprocess_error(&self, e: PreprocessError) -> Diagnostic {
        Diagnostic::error(e.message).at(self.asm_span(e.start, e.end), "")
    }

    /// Compile and validate a variant; diagnostics on failure.
    fn compile(&mut self, v: &Variant) -> Option<Compiled> {
        let mut full = v.derived.clone();
        if !full.ends_with('\n') {
            full.push('\n');
        }
        let iface_start = full.len();
        full.push_str(MATERIAL_INTERFACE);
        let iface_end = full.len();
        full.push('\n');
        full.push_str(v.extra);
        let iface = self.interface_file();
        let lines = LineMap::new(&v.derived, &self.asm.text);
        let map = |s: naga::Span| -> Option<Span> {
            let r = s.to_range()?;
            if r.start >= iface_start {
                return (r.start < iface_end).then(|| {
                    Span::new(
                        iface,
                        r.start - iface_start,
                        r.end.min(iface_end) - iface_start,
                    )
                });
            }
            let a = lines.map(r.start)?;
            let b = lines.map(r.end.min(iface_start)).unwrap_or(a).max(a);
            self.asm.map_span(a, b)
        };
        let fallback = self.file_start();
        let note = |d: Diagnostic| {
            if v.what.is_empty() {
                d
            } else {
                d.note(v.what.clone())
            }
        };
        let module = match naga::front::wgsl::parse_str(&full) {
            Ok(m) => m,
            Err(e) => {
                let mut d = Diagnostic::error(format!("WGSL: {}", sanitize(e.message())));
                let mut first = true;
                let mut labels: Vec<(Span, &str)> = e
                    .labels()
                    .map(|(s, l)| (map(s).unwrap_or(fallback), l))
                    .collect();
                // A clash with the interface (`redefinition of SurfaceInput`) is
                // the user's mistake: point at the user's text first.
                if let Some(i) = labels.iter().position(|(s, _)| s.file != iface) {
                    let user = labels.remove(i);
                    labels.insert(0, user);
                }
                for (sp, label) in labels {
                    d = if first {
                        d.at(sp, sanitize(label))
                    } else {
                        d.also(sp, sanitize(label))
                    };
                    first = false;
                }
                if first {
                    d = d.at(fallback, "");
                }
                for n in e.notes() {
                    d = d.note(sanitize(n));
                }
                self.diags.push(note(d));
                return None;
            }
        };
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        );
        if let Err(e) = validator.validate(&module) {
            // The innermost cause is the most specific message.
            let mut causes = vec![e.as_inner().to_string()];
            let mut src: &dyn std::error::Error = e.as_inner();
            while let Some(next) = src.source() {
                causes.push(next.to_string());
                src = next;
            }
            causes.retain(|c| !is_expression_invalid(c));
            let main = sanitize(causes.last().map(String::as_str).unwrap_or("invalid"));
            let mut d = Diagnostic::error(format!("WGSL validation: {main}"));
            let spans: Vec<Span> = e.spans().filter_map(|(s, _)| map(*s)).collect();
            match spans.split_last() {
                Some((last, rest)) => {
                    d = d.at(*last, "");
                    let context = causes
                        .first()
                        .filter(|_| causes.len() > 1)
                        .map(|c| sanitize(c))
                        .unwrap_or_default();
                    for s in rest {
                        if s != last {
                            d = d.also(*s, context.clone());
                        }
                    }
                }
                None => d = d.at(fallback, ""),
            }
            self.diags.push(note(d));
            return None;
        }
        Some(Compiled {
            module,
            lines,
            iface_start,
            iface_end,
            iface,
        })
    }

    fn check(&mut self, name: &str, shown: &str) -> Option<MaterialShader> {
        let text = self.asm.text.clone();
        // Reserved names.
        // (A tokenizer error is left for naga to report.)
        if let Ok(decls) = module_declarations(&text) {
            for (n, s, e) in decls {
                if n.starts_with("fx_") || n.starts_with("FX_") {
                    let sp = self.asm_span(s, e);
                    self.diags.push(
                        Diagnostic::error(format!(
                            "`{n}`: names starting with `fx_` or `FX_` are reserved for the engine"
                        ))
                        .at(sp, "reserved name"),
                    );
                }
            }
        }
        // Entry points: naga would complain about the interface's missing
        // `@location`s first.
        if let Ok(attrs) = find_attributes(&text, &["vertex", "fragment", "compute"]) {
            for (a, s, e) in attrs {
                let sp = self.asm_span(s, e);
                self.diags.push(
                    Diagnostic::error(format!(
                        "a material shader has no entry points: remove `@{a}`"
                    ))
                    .at(sp, "not allowed in a material shader")
                    .note("the engine generates the entry points around `surface` and `lighting`"),
                );
            }
        }
        if !self.diags.is_empty() {
            return None;
        }
        let used = features::feature_flags_used(&text);
        let used_refs: Vec<(String, i64)> = match self.kind {
            MaterialShaderKind::Surface => used.iter().map(|f| (f.clone(), 1)).collect(),
            MaterialShaderKind::Lighting => Vec::new(),
        };
        // 1. Preprocessed with every flag the text tests defined.
        let all = match preprocess(&text, &used_refs) {
            Ok((t, _)) => t,
            Err(e) => {
                let d = self.preprocess_error(e);
                self.diags.push(d);
                return None;
            }
        };
        let what_all = if used_refs.is_empty() {
            String::new()
        } else {
            format!(
                "with the feature flags {} defined",
                used.iter()
                    .map(|f| format!("`{f}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let compiled = self.compile(&Variant {
            what: what_all,
            derived: all,
            extra: "",
        })?;
        let mut shader = self.reflect(name, shown, &compiled)?;
        // Feature flags: known ones only.
        if self.kind == MaterialShaderKind::Surface {
            let flags = &shader.flags;
            for f in &used {
                if !flags.contains(f) && !defines(&text, f) {
                    let sp = directive_span(&text, f)
                        .map(|(s, e)| self.asm_span(s, e))
                        .unwrap_or_else(|| self.file_start());
                    let mut d =
                        Diagnostic::error(format!("`{f}` is not a feature flag of this shader"))
                            .at(sp, "never defined");
                    let names: Vec<&str> = flags.iter().map(String::as_str).collect();
                    d = match crate::script::ast::suggest(f, names.iter().copied()) {
                        Some(s) => d.note(format!("did you mean `{s}`?")),
                        None => d.note(format!("its flags: {}", names.join(", "))),
                    };
                    self.diags.push(d);
                }
            }
            shader.features = used.iter().filter(|f| flags.contains(f)).cloned().collect();
        }
        if !self.diags.is_empty() {
            return None;
        }
        if self.kind == MaterialShaderKind::Lighting || shader.features.is_empty() {
            return Some(shader);
        }
        // 2. With no flag defined: the same resources must be declared.
        let none = match preprocess(&text, &[]) {
            Ok((t, _)) => t,
            Err(e) => {
                let d = self.preprocess_error(e);
                self.diags.push(d);
                return None;
            }
        };
        let c_none = self.compile(&Variant {
            what: "with no feature flag defined".into(),
            derived: none,
            extra: "",
        })?;
        let bound = |m: &naga::Module| -> Vec<String> {
            let mut v: Vec<String> = m
                .global_variables
                .iter()
                .filter(|(_, g)| g.binding.is_some())
                .filter_map(|(_, g)| g.name.clone())
                .collect();
            v.sort();
            v
        };
        if bound(&compiled.module) != bound(&c_none.module) {
            self.diags.push(
                Diagnostic::error(
                    "resource declarations must not depend on feature flags: declare every texture, sampler and the params uniform outside `#ifdef` blocks",
                )
                .at(self.file_start(), ""),
            );
            return None;
        }
        // 3. and 4. Override and branch modes: feature blocks as `if` statements.
        let flags: Vec<&str> = shader.flags.iter().map(String::as_str).collect();
        let conv = |cond: &dyn Fn(&str) -> String| {
            convert_features(&text, &flags, cond).and_then(|t| preprocess(&t, &[]).map(|r| r.0))
        };
        let override_text = match conv(&|f: &str| f.to_string()) {
            Ok(mut t) => {
                t.push_str(&features::override_declarations(&flags));
                t
            }
            Err(e) => {
                let d = self.preprocess_error(e);
                self.diags.push(d);
                return None;
            }
        };
        self.compile(&Variant {
            what: "in override mode, where each feature `#ifdef` block becomes an `if` statement on an `override` constant: a block must hold whole statements and declare nothing used after it".into(),
            derived: override_text,
            extra: "",
        })?;
        let bit = |f: &str| {
            let i = flags.iter().position(|x| *x == f).unwrap_or(0);
            let lane = ["x", "y", "z", "w"][(i / 32).min(3)];
            format!("((fx_features.{lane} & {}u) != 0u)", 1u32 << (i % 32))
        };
        let branch_text = match conv(&bit) {
            Ok(t) => t,
            Err(e) => {
                let d = self.preprocess_error(e);
                self.diags.push(d);
                return None;
            }
        };
        self.compile(&Variant {
            what: "in branch mode, where each feature `#ifdef` block becomes an `if` statement on a run-time flag: a block must hold whole statements and declare nothing used after it".into(),
            derived: branch_text,
            extra: BRANCH_FEATURES_DECL,
        })?;
        Some(shader)
    }

    /// A span of the validated text, in its file.
    fn span_of(&self, c: &Compiled, s: naga::Span) -> Span {
        let Some(r) = s.to_range() else {
            return self.file_start();
        };
        if r.start >= c.iface_start {
            if r.start < c.iface_end {
                return Span::new(c.iface, r.start - c.iface_start, r.end - c.iface_start);
            }
            return self.file_start();
        }
        match c.lines.map(r.start) {
            Some(a) => {
                let b = c.lines.map(r.end).unwrap_or(a).max(a);
                self.asm_span(a, b)
            }
            None => self.file_start(),
        }
    }

    fn reflect(&mut self, name: &str, shown: &str, c: &Compiled) -> Option<MaterialShader> {
        let m = &c.module;
        let ctx = m.to_ctx();
        let kind = self.kind;
        let type_name = |h: naga::Handle<naga::Type>| ctx.type_to_string(h);
        let mut out = MaterialShader {
            name: name.to_string(),
            kind,
            label: shown.to_string(),
            file: self.root,
            text: String::new(),
            assembly: Assembly::default(),
            flags: Vec::new(),
            features: Vec::new(),
            params: None,
            params_binding: None,
            params_var: None,
            textures: Vec::new(),
            samplers: Vec::new(),
            lighting_takes_params: false,
        };
        // The function.
        let fname = kind.function();
        let expected = match kind {
            MaterialShaderKind::Surface => "fn surface(in: SurfaceInput) -> SurfaceOutput".to_string(),
            MaterialShaderKind::Lighting => "fn lighting(in: LightingInput) -> LightingOutput` or `fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput".to_string(),
        };
        let func = m
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(fname));
        let params_struct = m
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(kind.params_struct()));
        match func {
            None => {
                self.diags.push(
                    Diagnostic::error(format!(
                        "the {} shader defines no `{fname}` function",
                        match kind {
                            MaterialShaderKind::Surface => "surface",
                            MaterialShaderKind::Lighting => "lighting",
                        }
                    ))
                    .at(self.file_start(), format!("expected `{expected}`")),
                );
            }
            Some((h, f)) => {
                let is =
                    |ty: naga::Handle<naga::Type>, n: &str| m.types[ty].name.as_deref() == Some(n);
                let args = &f.arguments;
                let ok = match kind {
                    MaterialShaderKind::Surface => {
                        args.len() == 1
                            && is(args[0].ty, "SurfaceInput")
                            && f.result.as_ref().is_some_and(|r| is(r.ty, "SurfaceOutput"))
                    }
                    MaterialShaderKind::Lighting => {
                        (args.len() == 1 || args.len() == 2 && is(args[1].ty, "LightingParams"))
                            && is(args[0].ty, "LightingInput")
                            && f.result
                                .as_ref()
                                .is_some_and(|r| is(r.ty, "LightingOutput"))
                    }
                };
                if !ok {
                    let found_args: Vec<String> = args
                        .iter()
                        .map(|a| {
                            format!("{}: {}", a.name.as_deref().unwrap_or("_"), type_name(a.ty))
                        })
                        .collect();
                    let found = format!(
                        "fn {fname}({}){}",
                        found_args.join(", "),
                        f.result
                            .as_ref()
                            .map(|r| format!(" -> {}", type_name(r.ty)))
                            .unwrap_or_default()
                    );
                    let sp = self.signature_span(self.span_of(c, m.functions.get_span(h)));
                    self.diags.push(
                        Diagnostic::error(format!(
                            "`{fname}` must be `{expected}`; found `{found}`"
                        ))
                        .at(sp, "wrong signature"),
                    );
                }
                if kind == MaterialShaderKind::Lighting {
                    out.lighting_takes_params = args.len() == 2;
                    if args.len() == 1 {
                        if let Some((th, _)) = params_struct {
                            let sp = self.span_of(c, m.types.get_span(th));
                            let fsp = self.signature_span(self.span_of(c, m.functions.get_span(h)));
                            self.diags.push(
                                Diagnostic::error(
                                    "`LightingParams` is declared but `lighting` does not take it",
                                )
                                .at(fsp, "add `params: LightingParams` as a second parameter")
                                .also(sp, "declared here"),
                            );
                        }
                    }
                }
            }
        }
        // Resources.
        let mut uniform: Option<(String, u32, naga::Handle<naga::Type>, Span)> = None;
        let mut bindings: Vec<(u32, Span)> = Vec::new();
        for (h, gv) in m.global_variables.iter() {
            let gname = gv.name.clone().unwrap_or_default();
            let sp = self.span_of(c, m.global_variables.get_span(h));
            let Some(rb) = &gv.binding else {
                continue;
            };
            if kind == MaterialShaderKind::Lighting {
                self.diags.push(
                    Diagnostic::error(format!(
                        "a lighting shader declares no resources: `{gname}` is one"
                    ))
                    .at(sp, "not allowed in a lighting shader")
                    .note("lighting shaders run in the deferred light pass, where only the G-buffer exists: take values from `LightingInput` or `LightingParams`"),
                );
                continue;
            }
            if rb.group != MATERIAL_GROUP || rb.binding >= FIRST_ENGINE_BINDING {
                self.diags.push(
                    Diagnostic::error(format!(
                        "`{gname}` is at @group({}) @binding({}); surface shader resources are in @group(2) with bindings 0 to 15",
                        rb.group, rb.binding
                    ))
                    .at(sp, "bindings 16 and up and other groups are the engine's"),
                );
                continue;
            }
            if let Some((_, first)) = bindings.iter().find(|(b, _)| *b == rb.binding) {
                self.diags.push(
                    Diagnostic::error(format!("@binding({}) is used twice", rb.binding))
                        .at(sp, "second use")
                        .also(*first, "first use"),
                );
                continue;
            }
            bindings.push((rb.binding, sp));
            match &m.types[gv.ty].inner {
                TypeInner::Image {
                    dim: ImageDimension::D2,
                    arrayed: false,
                    class:
                        ImageClass::Sampled {
                            kind: ScalarKind::Float,
                            multi: false,
                        },
                } => match self.texture_notes(sp) {
                    Ok((srgb, description)) => out.textures.push(MaterialTexture {
                        flag: texture_flag(&gname),
                        name: gname,
                        binding: rb.binding,
                        srgb,
                        description,
                        span: sp,
                    }),
                    Err(d) => self.diags.push(d),
                },
                TypeInner::Sampler { comparison: false } => out.samplers.push(MaterialSampler {
                    name: gname,
                    binding: rb.binding,
                    span: sp,
                }),
                TypeInner::Struct { .. }
                    if gv.space == naga::AddressSpace::Uniform
                        && m.types[gv.ty].name.as_deref() == Some("SurfaceParams") =>
                {
                    if let Some((first, ..)) = &uniform {
                        self.diags.push(
                            Diagnostic::error(format!(
                                "`SurfaceParams` is bound twice (`{first}` and `{gname}`)"
                            ))
                            .at(sp, "second binding"),
                        );
                    } else {
                        uniform = Some((gname, rb.binding, gv.ty, sp));
                    }
                }
                _ if gv.space == naga::AddressSpace::Uniform => self.diags.push(
                    Diagnostic::error(format!(
                        "the uniform `{gname}` must have the type `SurfaceParams`; found `{}`",
                        type_name(gv.ty)
                    ))
                    .at(sp, "declare the parameters as fields of `struct SurfaceParams`"),
                ),
                _ => self.diags.push(
                    Diagnostic::error(format!(
                        "unsupported resource `{gname}` of type `{}` in a surface shader",
                        type_name(gv.ty)
                    ))
                    .at(
                        sp,
                        "a surface shader may declare texture_2d<f32>, sampler and one var<uniform> of SurfaceParams",
                    ),
                ),
            }
        }
        // Params.
        if let Some((th, t)) = params_struct {
            match (&t.inner, kind, &uniform) {
                (TypeInner::Struct { .. }, MaterialShaderKind::Surface, None) => {
                    let sp = self.span_of(c, m.types.get_span(th));
                    self.diags.push(
                        Diagnostic::error("`SurfaceParams` is declared but not bound")
                            .at(sp, "declared here")
                            .note(
                                "add `@group(2) @binding(0) var<uniform> material: SurfaceParams;`",
                            ),
                    );
                }
                (
                    TypeInner::Struct {
                        members,
                        span: size,
                    },
                    _,
                    _,
                ) => {
                    let decl = self.span_of(c, m.types.get_span(th));
                    out.params = Some(self.params(
                        m,
                        t.name.clone().unwrap_or_default(),
                        members,
                        *size,
                        decl,
                    ));
                }
                _ => {}
            }
        }
        if let Some((var, binding, _, _)) = uniform {
            out.params_binding = Some(binding);
            out.params_var = Some(var);
        }
        if kind == MaterialShaderKind::Surface {
            out.textures.sort_by_key(|t| t.binding);
            out.samplers.sort_by_key(|t| t.binding);
            out.flags = ENGINE_FLAGS.iter().map(|f| f.to_string()).collect();
            for t in &out.textures {
                if let Some(o) = out
                    .textures
                    .iter()
                    .find(|o| o.flag == t.flag && o.name != t.name)
                {
                    if o.binding < t.binding {
                        self.diags.push(
                            Diagnostic::error(format!(
                                "textures `{}` and `{}` have the same feature flag `{}`",
                                o.name, t.name, t.flag
                            ))
                            .at(t.span, "rename one of them"),
                        );
                    }
                }
                if ENGINE_FLAGS.contains(&t.flag.as_str()) {
                    self.diags.push(
                        Diagnostic::error(format!(
                            "texture `{}` would have the engine's feature flag `{}`",
                            t.name, t.flag
                        ))
                        .at(t.span, "rename it"),
                    );
                }
                out.flags.push(t.flag.clone());
            }
            if out.samplers.is_empty() && !out.textures.is_empty() {
                let t = &out.textures[0];
                self.diags.push(
                    Diagnostic::error("the shader declares textures but no sampler")
                        .at(t.span, "sampled with what?")
                        .note("add `@group(2) @binding(N) var material_sampler: sampler;`"),
                );
            }
        }
        Some(out)
    }

    /// `params` of a `SurfaceParams`/`LightingParams` struct with annotations.
    fn params(
        &mut self,
        m: &naga::Module,
        struct_name: String,
        members: &[naga::StructMember],
        size: u32,
        decl: Span,
    ) -> MaterialParams {
        let file_text = self.sources.get(decl.file).text.clone();
        let decl_text = &file_text[decl.start as usize..(decl.end as usize).min(file_text.len())];
        let mut out = Vec::new();
        for mem in members {
            let mname = mem.name.clone().unwrap_or_default();
            let ty = match m.types[mem.ty].inner {
                TypeInner::Scalar(s) => scalar_field(s, 1),
                TypeInner::Vector { size, scalar } => scalar_field(scalar, size as u8),
                TypeInner::Matrix {
                    columns: naga::VectorSize::Quad,
                    rows: naga::VectorSize::Quad,
                    scalar,
                } if scalar.kind == ScalarKind::Float && scalar.width == 4 => Some(FieldType::Mat4),
                _ => None,
            };
            let (mspan, default, range, description) =
                member_annotations(decl_text, decl.start as usize, &mname, decl.file);
            let span = mspan.unwrap_or(decl);
            match ty {
                Some(ty) => {
                    if let Some(d) = &default {
                        if d.len() != ty.components() {
                            self.diags.push(
                                Diagnostic::error(format!(
                                    "`@default` of `{mname}` has {} values, the field has {}",
                                    d.len(),
                                    ty.components()
                                ))
                                .at(span, "wrong default"),
                            );
                        }
                    }
                    out.push(UniformMember {
                        name: mname,
                        offset: mem.offset,
                        ty,
                        span,
                        default,
                        range,
                        description,
                    })
                }
                None => self.diags.push(
                    Diagnostic::error(format!(
                        "parameter `{mname}` has the unsupported type `{}`",
                        m.to_ctx().type_to_string(mem.ty)
                    ))
                    .at(span, "use f32, i32, u32, their vectors, or mat4x4<f32>"),
                ),
            }
        }
        MaterialParams {
            struct_name,
            size,
            members: out,
            span: decl,
        }
    }

    /// The `// @srgb description` after a texture declaration.
    fn texture_notes(&self, decl: Span) -> Result<(bool, String), Diagnostic> {
        let text = &self.sources.get(decl.file).text;
        let end = (decl.end as usize).min(text.len());
        let line_end = text[end..]
            .find('\n')
            .map(|i| end + i)
            .unwrap_or(text.len());
        let rest = &text[end..line_end];
        let Some(c) = rest.find("//") else {
            return Ok((false, String::new()));
        };
        let comment = rest[c + 2..].trim();
        let (word, tail) = match comment.strip_prefix('@') {
            Some(r) => {
                let n = r
                    .find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_'))
                    .unwrap_or(r.len());
                (Some(&r[..n]), r[n..].trim())
            }
            None => (None, comment),
        };
        match word {
            None => Ok((false, tail.to_string())),
            Some("srgb") => Ok((true, tail.to_string())),
            Some("linear") => Ok((false, tail.to_string())),
            Some(w) => {
                let at = end + c + 2 + (rest[c + 2..].len() - rest[c + 2..].trim_start().len());
                Err(
                    Diagnostic::error(format!("unknown texture annotation `@{w}`")).at(
                        Span::new(decl.file, at, at + 1 + w.len()),
                        "expected `@srgb` or `@linear`",
                    ),
                )
            }
        }
    }

    /// A function's span cut to its first line (the signature).
    fn signature_span(&self, sp: Span) -> Span {
        let text = &self.sources.get(sp.file).text;
        let s = (sp.start as usize).min(text.len());
        let e = (sp.end as usize).min(text.len());
        let cut = text[s..e]
            .find(['{', '\n'])
            .map(|i| s + text[s..s + i].trim_end().len())
            .unwrap_or(e);
        Span::new(sp.file, s, cut.max(s))
    }
}

fn scalar_field(s: naga::Scalar, n: u8) -> Option<FieldType> {
    match (s.kind, s.width) {
        (ScalarKind::Float, 4) => Some(FieldType::F32(n)),
        (ScalarKind::Sint, 4) => Some(FieldType::I32(n)),
        (ScalarKind::Uint, 4) => Some(FieldType::U32(n)),
        _ => None,
    }
}

/// Whether the text `#define`s `name`.
fn defines(text: &str, name: &str) -> bool {
    text.lines().any(|l| {
        let mut w = l.split_whitespace();
        w.next() == Some("#define") && w.next() == Some(name)
    })
}

/// The byte range of the first `#ifdef name` / `#ifndef name` line's directive.
fn directive_span(text: &str, name: &str) -> Option<(usize, usize)> {
    let mut off = 0;
    for line in text.split_inclusive('\n') {
        let t = line.trim();
        let mut w = t.split_whitespace();
        if matches!(w.next(), Some("#ifdef" | "#ifndef")) && w.next() == Some(name) {
            let s = off + (line.len() - line.trim_start().len());
            return Some((s, s + t.len()));
        }
        off += line.len();
    }
    None
}

fn is_expression_invalid(c: &str) -> bool {
    c.strip_prefix("Expression [")
        .and_then(|r| r.strip_suffix("] is invalid"))
        .is_some_and(|n| n.chars().all(|ch| ch.is_ascii_digit()))
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shader::include::tests::MemFs;
    use crate::shader::rename::prefix_module_names;

    const SURFACES: &[&str] = &["standard", "triplanar"];
    const LIGHTINGS: &[&str] = &["lambert", "phong", "blinn_phong", "cook_torrance"];

    fn load(kind: MaterialShaderKind, name: &str) -> (MaterialShader, SourceMap) {
        let mut sources = SourceMap::new();
        let file = find_material_shader(name, None).expect("built-in");
        match load_material_shader(kind, name, file, &mut sources) {
            Ok(m) => (m, sources),
            Err(ds) => panic!(
                "{}",
                ds.iter().map(|d| d.render(&sources)).collect::<String>()
            ),
        }
    }

    fn validate(wgsl: &str) {
        let m = naga::front::wgsl::parse_str(wgsl)
            .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&m)
        .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
    }

    /// Load a memory file through `fs` (paths under /m).
    fn load_mem(
        kind: MaterialShaderKind,
        fs: &MemFs,
        path: &str,
    ) -> (Result<MaterialShader, Vec<Diagnostic>>, SourceMap) {
        let mut sources = SourceMap::new();
        let file = ShaderFile {
            shown: path.trim_start_matches("/m/").to_string(),
            text: fs.files[Path::new(path)].clone(),
            path: Some(path.into()),
        };
        let r = load_material_shader_with(kind, "t", file, fs, &mut sources);
        (r, sources)
    }

    fn errors(r: Result<MaterialShader, Vec<Diagnostic>>, sources: &SourceMap) -> String {
        match r {
            Ok(_) => panic!("expected errors"),
            Err(ds) => ds.iter().map(|d| d.render(sources)).collect(),
        }
    }

    #[test]
    fn library_lists() {
        let mut names = builtin_material_shaders();
        names.sort();
        assert_eq!(
            names,
            [
                "blinn_phong",
                "cook_torrance",
                "lambert",
                "phong",
                "standard",
                "triplanar"
            ]
        );
        assert!(embedded_material_shader("lib/brdf.wgsl").is_some());
        assert!(embedded_material_shader("lib/normal.wgsl").is_some());
        assert!(find_material_shader("lib/brdf", None).is_none());
        assert!(find_material_shader("../shaders/blurX", None).is_none());
        for (name, text) in EMBEDDED_MATERIAL_SHADERS {
            assert!(text.starts_with("//"), "{name} has no header comment");
        }
    }

    #[test]
    fn library_surfaces_in_every_mode() {
        for name in SURFACES {
            let (m, _) = load(MaterialShaderKind::Surface, name);
            assert!(!m.features.is_empty(), "{name}");
            let flags: Vec<&str> = m.flags.iter().map(String::as_str).collect();
            let none: &[&str] = &[];
            for enabled in [flags.as_slice(), none, &flags[..flags.len() / 2]] {
                let t = m
                    .wgsl(FeatureMode::Preprocess, enabled, &|f| f.into())
                    .unwrap();
                validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
            }
            let t = m.wgsl(FeatureMode::Override, &[], &|f| f.into()).unwrap();
            assert_eq!(
                t.lines().count(),
                m.text.lines().count() + flags.len(),
                "{name}: override mode keeps the lines"
            );
            for f in &flags {
                assert!(t.contains(&format!("override {f}: bool = false;")));
            }
            validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
            let t = m
                .wgsl(FeatureMode::Branch, &[], &|f| {
                    let i = flags.iter().position(|x| *x == f).unwrap();
                    format!("((fx_features.x & {}u) != 0u)", 1u32 << i)
                })
                .unwrap();
            assert!(t.contains("if ((fx_features.x & "));
            validate(&format!(
                "{t}\n{MATERIAL_INTERFACE}\n{BRANCH_FEATURES_DECL}"
            ));
        }
    }

    #[test]
    fn library_lightings() {
        for name in LIGHTINGS {
            let (m, _) = load(MaterialShaderKind::Lighting, name);
            assert!(m.textures.is_empty() && m.flags.is_empty());
            assert_eq!(
                m.lighting_takes_params,
                matches!(*name, "phong" | "blinn_phong"),
                "{name}"
            );
            for mode in [
                FeatureMode::Preprocess,
                FeatureMode::Override,
                FeatureMode::Branch,
            ] {
                let t = m.wgsl(mode, &[], &|f| f.into()).unwrap();
                validate(&format!("{t}\n{MATERIAL_INTERFACE}"));
            }
        }
        let (phong, _) = load(MaterialShaderKind::Lighting, "phong");
        let p = phong.params.unwrap();
        assert_eq!(p.struct_name, "LightingParams");
        assert_eq!(p.members.len(), 1);
        let m = &p.members[0];
        assert_eq!(
            (m.name.as_str(), m.ty, m.default.clone(), m.range),
            (
                "specular_power",
                FieldType::F32(1),
                Some(vec![32.0]),
                Some((1.0, 4096.0))
            )
        );
        assert!(m.description.contains("SPECULAR_POWER"));
        let (bp, _) = load(MaterialShaderKind::Lighting, "blinn_phong");
        assert_eq!(bp.params.unwrap().members[0].name, "shininess");
    }

    #[test]
    fn renamed_lighting_shaders_share_a_module() {
        let mut module = String::new();
        for (i, name) in LIGHTINGS.iter().enumerate() {
            let (m, _) = load(MaterialShaderKind::Lighting, name);
            let t = m.lighting_wgsl(&format!("lm{i}_")).unwrap();
            assert!(t.contains(&format!("fn lm{i}_lighting(")), "{t}");
            module.push_str(&t);
        }
        // Also by hand, as the brief's minimal case: two shaders with the same names.
        let (a, _) = load(MaterialShaderKind::Lighting, "phong");
        let (b, _) = load(MaterialShaderKind::Lighting, "cook_torrance");
        let (ta, _) = preprocess(&a.text, &[]).unwrap();
        let (tb, _) = preprocess(&b.text, &[]).unwrap();
        let two = format!(
            "{}{}{MATERIAL_INTERFACE}",
            prefix_module_names(&ta, "lm0_", INTERFACE_NAMES).unwrap(),
            prefix_module_names(&tb, "lm1_", INTERFACE_NAMES).unwrap()
        );
        assert!(two.contains("struct lm0_LightingParams"));
        assert!(two.contains("params: lm0_LightingParams"));
        assert!(two.contains("params.specular_power"));
        validate(&two);
        // And they can be called from generated code.
        validate(&format!(
            "{module}{MATERIAL_INTERFACE}\nfn fx_test(i: LightingInput) -> vec3<f32> {{\n    let a = lm0_lighting(i);\n    let b = lm1_lighting(i, lm1_LightingParams(32.0));\n    return a.diffuse + b.specular;\n}}\n"
        ));
    }

    #[test]
    fn standard_params_and_textures() {
        let (m, _) = load(MaterialShaderKind::Surface, "standard");
        let p = m.params.as_ref().unwrap();
        assert_eq!(p.struct_name, "SurfaceParams");
        let get = |n: &str| p.members.iter().find(|x| x.name == n).unwrap();
        assert_eq!(get("base_color").default, Some(vec![1.0; 4]));
        assert_eq!(get("emissive").ty, FieldType::F32(3));
        assert_eq!(get("specular").default, Some(vec![0.04; 3]));
        assert_eq!(get("roughness").range, Some((0.0, 1.0)));
        assert_eq!(get("detail_scale").default, Some(vec![8.0]));
        // vec3s are followed by f32s, so nothing is wasted before the maps.
        assert_eq!(get("metallic").offset, 28);
        assert_eq!(get("roughness").offset, 44);
        assert_eq!(get("base_color_map_uv").offset, 64);
        assert_eq!(p.size, 320);
        let maps = [
            ("base_color_map", true),
            ("normal_map", false),
            ("metallic_roughness_map", false),
            ("occlusion_map", false),
            ("emissive_map", true),
            ("specular_map", true),
            ("opacity_map", false),
            ("detail_map", true),
        ];
        assert_eq!(m.textures.len(), maps.len());
        for (t, (name, srgb)) in m.textures.iter().zip(maps) {
            assert_eq!((t.name.as_str(), t.srgb), (name, srgb));
            assert_eq!(
                get(&format!("{name}_uv")).default,
                Some(vec![1.0, 0.0, 0.0, 1.0])
            );
            assert_eq!(
                get(&format!("{name}_uv_offset")).default,
                Some(vec![0.0; 4])
            );
            assert!(m.features.contains(&t.flag), "{} unused", t.flag);
        }
        assert_eq!(m.params_binding, Some(0));
        assert_eq!(m.params_var.as_deref(), Some("material"));
        assert_eq!(m.samplers.len(), 1);
        assert!(m.features.contains(&"HAS_VERTEX_COLOR".to_string()));
        assert!(m.features.contains(&"HAS_TANGENTS".to_string()));
        let (t, _) = load(MaterialShaderKind::Surface, "triplanar");
        let names: Vec<&str> = t
            .params
            .as_ref()
            .unwrap()
            .members
            .iter()
            .map(|m| m.name.as_str())
            .collect();
        assert_eq!(
            names,
            [
                "base_color",
                "specular",
                "metallic",
                "roughness",
                "scale",
                "sharpness",
                "normal_scale"
            ]
        );
        let tex: Vec<(&str, bool)> = t
            .textures
            .iter()
            .map(|t| (t.name.as_str(), t.srgb))
            .collect();
        assert_eq!(tex, [("base_color_map", true), ("normal_map", false)]);
    }

    const GOOD_SURFACE: &str = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    o.normal = in.normal;\n    return o;\n}\n";

    #[test]
    fn type_error_at_users_line_and_column() {
        let src = "#include \"lib/normal.wgsl\"\n\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_VERTEX_COLOR\n    o.diffuse = in.color.rgb;\n#endif\n    let k: f32 = in.normal;\n    return o;\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        assert_eq!(
            errors(r, &sources),
            "s.wgsl:8:9: error: WGSL: the type of `k` is expected to be `f32`, but got `vec3<f32>`\n  |\n8 |     let k: f32 = in.normal;\n  |         ^ definition of `k`\n  = note: with the feature flags `HAS_VERTEX_COLOR` defined\n"
        );
        // A validation error (not caught by the front end).
        let src = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    o.diffuse = in.normal + in.uv0.xy;\n    return o;\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(text.starts_with("s.wgsl:3:17: error: WGSL"), "{text}");
        assert!(
            !text.contains("Vector {") && !text.contains("Scalar {"),
            "{text}"
        );
    }

    #[test]
    fn error_inside_included_file() {
        let fs = MemFs::default()
            .file(
                "/m/s.wgsl",
                &format!("#include \"inc/helpers.wgsl\"\n{GOOD_SURFACE}"),
            )
            .file(
                "/m/inc/helpers.wgsl",
                "// helpers\nfn twice(x: f32) -> f32 {\n    return x * undefined_name;\n}\n",
            );
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with("/m/inc/helpers.wgsl:3:16: error: WGSL: no definition in scope for identifier: `undefined_name`\n  |\n3 |     return x * undefined_name;\n  |                ^^^^^^^^^^^^^^"),
            "{text}"
        );
        // A missing include: at the directive.
        let fs = MemFs::default().file(
            "/m/s.wgsl",
            &format!("{GOOD_SURFACE}  #include \"gone.wgsl\"\n"),
        );
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        assert!(errors(r, &sources)
            .starts_with("s.wgsl:6:3: error: cannot find included file `gone.wgsl`"));
    }

    #[test]
    fn wrong_signature() {
        let src = "fn surface(in: SurfaceInput) -> vec4<f32> {\n    return vec4<f32>(1.0);\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        assert_eq!(
            errors(r, &sources),
            "s.wgsl:1:1: error: `surface` must be `fn surface(in: SurfaceInput) -> SurfaceOutput`; found `fn surface(in: SurfaceInput) -> vec4<f32>`\n  |\n1 | fn surface(in: SurfaceInput) -> vec4<f32> {\n  | ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^ wrong signature\n"
        );
        let fs = MemFs::default().file("/m/s.wgsl", "fn surfac(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    return o;\n}\n");
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        assert!(errors(r, &sources)
            .starts_with("s.wgsl:1:1: error: the surface shader defines no `surface` function"));
        let fs = MemFs::default().file("/m/l.wgsl", "fn lighting(in: LightingInput, k: f32) -> LightingOutput {\n    return LightingOutput(in.light * k, vec3<f32>(0.0));\n}\n");
        let (r, sources) = load_mem(MaterialShaderKind::Lighting, &fs, "/m/l.wgsl");
        assert!(errors(r, &sources)
            .contains("found `fn lighting(in: LightingInput, k: f32) -> LightingOutput`"));
    }

    #[test]
    fn interface_clash_and_entry_points() {
        let src = format!("struct SurfaceInput {{ a: f32 }}\n{GOOD_SURFACE}");
        let fs = MemFs::default().file("/m/s.wgsl", &src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with("s.wgsl:1:8: error: WGSL: redefinition of `SurfaceInput`"),
            "{text}"
        );
        let src = format!("@fragment\n{GOOD_SURFACE}");
        let fs = MemFs::default().file("/m/s.wgsl", &src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with(
                "s.wgsl:1:1: error: a material shader has no entry points: remove `@fragment`"
            ),
            "{text}"
        );
    }

    #[test]
    fn lighting_with_texture_rejected() {
        let src = "@group(2) @binding(0) var t: texture_2d<f32>;\nfn lighting(in: LightingInput) -> LightingOutput {\n    return LightingOutput(in.light, vec3<f32>(0.0));\n}\n";
        let fs = MemFs::default().file("/m/l.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Lighting, &fs, "/m/l.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with(
                "l.wgsl:1:23: error: a lighting shader declares no resources: `t` is one\n"
            ),
            "{text}"
        );
    }

    #[test]
    fn surface_resource_rules() {
        let src = format!(
            "struct SurfaceParams {{\n    k: f32, // @default(1, 2)\n}}\n@group(2) @binding(0) var<uniform> p: SurfaceParams;\n@group(2) @binding(16) var a: texture_2d<f32>;\n@group(1) @binding(1) var b: texture_2d<f32>;\n@group(2) @binding(2) var c: texture_2d<f32>; // @gamma\n@group(2) @binding(3) var<storage> d: array<f32>;\n@group(2) @binding(0) var s: sampler;\nfn fx_helper() {{}}\n{GOOD_SURFACE}"
        );
        let fs = MemFs::default().file("/m/s.wgsl", &src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.contains("s.wgsl:10:4: error: `fx_helper`: names starting with `fx_`"),
            "{text}"
        );
        let src = src.replace("fn fx_helper() {}\n", "");
        let fs = MemFs::default().file("/m/s.wgsl", &src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        for want in [
            "s.wgsl:5:24: error: `a` is at @group(2) @binding(16)",
            "s.wgsl:6:23: error: `b` is at @group(1) @binding(1)",
            "s.wgsl:7:50: error: unknown texture annotation `@gamma`",
            "s.wgsl:8:23: error: unsupported resource `d` of type `array<f32>`",
            "s.wgsl:9:23: error: @binding(0) is used twice",
            "s.wgsl:2:5: error: `@default` of `k` has 2 values, the field has 1",
        ] {
            assert!(text.contains(want), "missing {want:?} in\n{text}");
        }
    }

    #[test]
    fn feature_rules() {
        // A typo in a texture flag.
        let src = "@group(2) @binding(0) var base_map: texture_2d<f32>;\n@group(2) @binding(1) var smp: sampler;\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_BASEMAP\n    o.diffuse = textureSample(base_map, smp, in.uv0).rgb;\n#endif\n    return o;\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with(
                "s.wgsl:5:1: error: `HAS_BASEMAP` is not a feature flag of this shader"
            ),
            "{text}"
        );
        assert!(text.contains("did you mean `HAS_BASE_MAP`?"), "{text}");
        // Fixed, it loads; the flag is known.
        let fs = MemFs::default().file("/m/s.wgsl", &src.replace("HAS_BASEMAP", "HAS_BASE_MAP"));
        let (r, _) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let m = r.unwrap();
        assert_eq!(m.features, ["HAS_BASE_MAP"]);
        assert_eq!(m.flags.last().map(String::as_str), Some("HAS_BASE_MAP"));
        // A block that declares something used after it: fine when preprocessed,
        // wrong as an `if` statement.
        let src = "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n#ifdef HAS_UV1\n    let uv = in.uv1;\n#else\n    let uv = in.uv0;\n#endif\n    o.roughness = uv.x;\n    return o;\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        let text = errors(r, &sources);
        assert!(
            text.starts_with(
                "s.wgsl:8:19: error: WGSL: no definition in scope for identifier: `uv`"
            ),
            "{text}"
        );
        assert!(text.contains("note: in override mode"), "{text}");
        // A flag around a declaration.
        let src = "#ifdef HAS_UV1\nconst K = 1.0;\n#endif\nfn surface(in: SurfaceInput) -> SurfaceOutput {\n    var o: SurfaceOutput;\n    return o;\n}\n";
        let fs = MemFs::default().file("/m/s.wgsl", src);
        let (r, sources) = load_mem(MaterialShaderKind::Surface, &fs, "/m/s.wgsl");
        assert!(errors(r, &sources)
            .starts_with("s.wgsl:1:1: error: feature flag `HAS_UV1` used outside a function"));
    }

    #[test]
    fn sanitized_types() {
        assert_eq!(
            sanitize("Operation Add can't work with [2] (of type Vector { size: Tri, scalar: Scalar { kind: Float, width: 4 } }) and [4] (of type Matrix { columns: Bi, rows: Bi, scalar: Scalar { kind: Float, width: 4 } })"),
            "Operation Add can't work with `vec3<f32>` and `mat2x2<f32>`"
        );
        assert_eq!(
            sanitize("Function [0] 'f' is invalid"),
            "function `f` is invalid"
        );
        assert_eq!(sanitize("x[3] ok"), "x[3] ok");
    }
}
