//! The [`Checker`]: a material shader's text checked for reserved names and entry
//! points, then compiled and validated by naga in every way the renderer compiles
//! it (all feature flags defined, none, override mode, branch mode), with naga's
//! errors mapped back to the user's files. Reading the validated module is in
//! [`super::reflect`].

use super::{
    sanitize, MaterialShader, MaterialShaderKind, BRANCH_FEATURES_DECL, MATERIAL_INTERFACE,
    MATERIAL_INTERFACE_SHOWN,
};
use crate::script::{Diagnostic, FileId, SourceMap, Span};
use crate::shader::features::{self, convert_features};
use crate::shader::include::{Assembly, LineMap};
use crate::shader::preprocess::{lines_with_offsets, preprocess, PreprocessError};
use crate::shader::rename::{find_attributes, module_declarations};

/// One way the checks compile the text.
struct Variant {
    /// What the variant is, for a note on its errors.
    what: String,
    /// The text derived line by line from the assembly (plus appended lines).
    derived: String,
    /// Appended after the interface.
    extra: &'static str,
}

pub(super) struct Checker<'a> {
    pub(super) kind: MaterialShaderKind,
    pub(super) asm: &'a Assembly,
    pub(super) root: FileId,
    pub(super) sources: &'a mut SourceMap,
    pub(super) diags: Vec<Diagnostic>,
}

/// A validated variant: the module, its full text, and how to map its spans.
pub(super) struct Compiled {
    pub(super) module: naga::Module,
    lines: LineMap,
    iface_start: usize,
    iface_end: usize,
    iface: FileId,
}

impl Checker<'_> {
    pub(super) fn file_start(&self) -> Span {
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
    pub(super) fn asm_span(&self, start: usize, end: usize) -> Span {
        self.asm
            .map_span(start, end)
            .unwrap_or_else(|| self.file_start())
    }

    fn preprocess_error(&self, e: PreprocessError) -> Diagnostic {
        Diagnostic::error(e.message).at(self.asm_span(e.start, e.end), "")
    }

    /// `text` with each feature block of `flags` turned into an `if` statement on
    /// `cond(flag)`, then preprocessed; a failure goes to the diagnostics.
    fn features_as_ifs(
        &mut self,
        text: &str,
        flags: &[&str],
        cond: &dyn Fn(&str) -> String,
    ) -> Option<String> {
        match convert_features(text, flags, cond).and_then(|t| preprocess(&t, &[]).map(|r| r.0)) {
            Ok(t) => Some(t),
            Err(e) => {
                let d = self.preprocess_error(e);
                self.diags.push(d);
                None
            }
        }
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
                let d = parse_error(&e, &map, fallback, iface);
                self.diags.push(note(d));
                return None;
            }
        };
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        );
        if let Err(e) = validator.validate(&module) {
            let d =
                crate::shader::wgsl_names::validation_diagnostic(&e, &module, &full, map, fallback);
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

    pub(super) fn check(&mut self, name: &str, shown: &str) -> Option<MaterialShader> {
        let text = self.asm.text.clone();
        self.check_reserved_names(&text);
        self.check_no_entry_points(&text);
        if !self.diags.is_empty() {
            return None;
        }
        let used = features::feature_flags_used(&text);
        let compiled = self.compile_with_flags_defined(&text, &used)?;
        let mut shader = self.reflect(name, shown, &compiled)?;
        if self.kind == MaterialShaderKind::Surface {
            self.check_feature_flags(&text, &used, &mut shader);
        }
        if !self.diags.is_empty() {
            return None;
        }
        if self.kind == MaterialShaderKind::Lighting || shader.features.is_empty() {
            return Some(shader);
        }
        self.check_resources_without_flags(&text, &compiled)?;
        self.check_feature_modes(&text, &shader)?;
        Some(shader)
    }

    /// Names starting with `fx_` or `FX_` are the engine's. (A tokenizer error
    /// is left for naga to report.)
    fn check_reserved_names(&mut self, text: &str) {
        if let Ok(decls) = module_declarations(text) {
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
    }

    /// Entry points: naga would complain about the interface's missing
    /// `@location`s first.
    fn check_no_entry_points(&mut self, text: &str) {
        if let Ok(attrs) = find_attributes(text, &["vertex", "fragment", "compute"]) {
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
    }

    /// Step 1: the text preprocessed with every flag it tests defined (a
    /// surface shader's; a lighting shader has none), compiled.
    fn compile_with_flags_defined(&mut self, text: &str, used: &[String]) -> Option<Compiled> {
        let used_refs: Vec<(String, i64)> = match self.kind {
            MaterialShaderKind::Surface => used.iter().map(|f| (f.clone(), 1)).collect(),
            MaterialShaderKind::Lighting => Vec::new(),
        };
        let all = match preprocess(text, &used_refs) {
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
        self.compile(&Variant {
            what: what_all,
            derived: all,
            extra: "",
        })
    }

    /// Feature flags: known ones only; the shader's features are the known
    /// flags its text tests.
    fn check_feature_flags(&mut self, text: &str, used: &[String], shader: &mut MaterialShader) {
        let flags = &shader.flags;
        for f in used {
            if !flags.contains(f) && !defines(text, f) {
                let sp = directive_span(text, f)
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

    /// Step 2: with no flag defined, the same resources must be declared as
    /// in `compiled` (every flag defined).
    fn check_resources_without_flags(&mut self, text: &str, compiled: &Compiled) -> Option<()> {
        let none = match preprocess(text, &[]) {
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
        Some(())
    }

    /// Steps 3 and 4: override and branch modes, feature blocks as `if`
    /// statements.
    fn check_feature_modes(&mut self, text: &str, shader: &MaterialShader) -> Option<()> {
        let flags: Vec<&str> = shader.flags.iter().map(String::as_str).collect();
        let mut override_text = self.features_as_ifs(text, &flags, &|f: &str| f.to_string())?;
        override_text.push_str(&features::override_declarations(&flags));
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
        let branch_text = self.features_as_ifs(text, &flags, &bit)?;
        self.compile(&Variant {
            what: "in branch mode, where each feature `#ifdef` block becomes an `if` statement on a run-time flag: a block must hold whole statements and declare nothing used after it".into(),
            derived: branch_text,
            extra: BRANCH_FEATURES_DECL,
        })?;
        Some(())
    }

    /// A span of the validated text, in its file.
    pub(super) fn span_of(&self, c: &Compiled, s: naga::Span) -> Span {
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
    for (off, line) in lines_with_offsets(text) {
        let t = line.trim();
        let mut w = t.split_whitespace();
        if matches!(w.next(), Some("#ifdef" | "#ifndef")) && w.next() == Some(name) {
            let s = off + (line.len() - line.trim_start().len());
            return Some((s, s + t.len()));
        }
    }
    None
}

/// naga's parse error `e` in the user's files (`map` maps its spans, `fallback`
/// where it maps none): a clash with the interface (`redefinition of
/// SurfaceInput`) is the user's mistake, so the user's text is pointed at first.
fn parse_error(
    e: &naga::front::wgsl::ParseError,
    map: &dyn Fn(naga::Span) -> Option<Span>,
    fallback: Span,
    iface: FileId,
) -> Diagnostic {
    let mut d = Diagnostic::error(format!("WGSL: {}", sanitize(e.message())));
    let mut first = true;
    let mut labels: Vec<(Span, &str)> = e
        .labels()
        .map(|(s, l)| (map(s).unwrap_or(fallback), l))
        .collect();
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
    d
}
