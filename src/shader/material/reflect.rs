//! Reading a validated material shader: its `surface` / `lighting` function's
//! signature and the annotated params struct (its resources and feature flags
//! are read in `resources.rs`). The second half of the [`Checker`].

use super::check::{Checker, Compiled};
use super::{MaterialParams, MaterialShader, MaterialShaderKind};
use crate::script::{Diagnostic, Span};
use crate::shader::include::Assembly;
use crate::shader::reflect::{member_annotations, UniformMember};
use naga::common::wgsl::TypeContext as _;
use naga::TypeInner;

impl Checker<'_> {
    pub(super) fn reflect(
        &mut self,
        name: &str,
        shown: &str,
        c: &Compiled,
    ) -> Option<MaterialShader> {
        let m = &c.module;
        let kind = self.kind;
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
            environment: None,
        };
        let params_struct = m
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(kind.params_struct()));
        self.check_entry_function(c, params_struct, &mut out);
        if kind == MaterialShaderKind::Lighting {
            self.reflect_environment(c, &mut out);
        }
        self.reflect_resources(c, &mut out);
        if let Some(params_struct) = params_struct {
            self.reflect_params(c, params_struct, &mut out);
        }
        if kind == MaterialShaderKind::Surface {
            self.reflect_texture_flags(&mut out);
        }
        Some(out)
    }

    /// The `surface` / `lighting` function: it must exist with the expected
    /// signature; a lighting shader declaring `LightingParams` must take them.
    fn check_entry_function(
        &mut self,
        c: &Compiled,
        params_struct: Option<(naga::Handle<naga::Type>, &naga::Type)>,
        out: &mut MaterialShader,
    ) {
        let m = &c.module;
        let kind = self.kind;
        let fname = kind.name();
        let expected = match kind {
            MaterialShaderKind::Surface => "fn surface(in: SurfaceInput) -> SurfaceOutput".to_string(),
            MaterialShaderKind::Lighting => "fn lighting(in: LightingInput) -> LightingOutput` or `fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput".to_string(),
        };
        let Some((h, f)) = m
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(fname))
        else {
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
            return;
        };
        if !self.has_entry_signature(m, f) {
            let found = found_signature(m, fname, f);
            let sp = self.signature_span(self.span_of(c, m.functions.get_span(h)));
            self.diags.push(
                Diagnostic::error(format!("`{fname}` must be `{expected}`; found `{found}`"))
                    .at(sp, "wrong signature"),
            );
        }
        let args = &f.arguments;
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

    /// True when `f` has the argument and result types this kind of shader's
    /// function must have.
    fn has_entry_signature(&self, m: &naga::Module, f: &naga::Function) -> bool {
        let is = |ty: naga::Handle<naga::Type>, n: &str| m.types[ty].name.as_deref() == Some(n);
        let args = &f.arguments;
        match self.kind {
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
        }
    }

    /// The `SurfaceParams` / `LightingParams` struct: its annotated members, or
    /// an error when a surface shader declares it without binding it.
    fn reflect_params(
        &mut self,
        c: &Compiled,
        (th, t): (naga::Handle<naga::Type>, &naga::Type),
        out: &mut MaterialShader,
    ) {
        let m = &c.module;
        match (&t.inner, self.kind, &out.params_var) {
            (TypeInner::Struct { .. }, MaterialShaderKind::Surface, None) => {
                let sp = self.span_of(c, m.types.get_span(th));
                self.diags.push(
                    Diagnostic::error("`SurfaceParams` is declared but not bound")
                        .at(sp, "declared here")
                        .note("add `@group(2) @binding(0) var<uniform> material: SurfaceParams;`"),
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
                out.params =
                    Some(self.params(m, t.name.clone().unwrap_or_default(), members, *size, decl));
            }
            _ => {}
        }
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
            let ty = crate::shader::reflect::field_type(m, mem.ty);
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

impl Checker<'_> {
    /// A lighting shader's optional `environment` function: its signature must
    /// be `fn environment(in: EnvironmentInput) -> LightingOutput`, with
    /// `params: LightingParams` as a second parameter when `lighting` takes one.
    fn reflect_environment(&mut self, c: &Compiled, out: &mut MaterialShader) {
        let m = &c.module;
        let Some((h, f)) = m
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some("environment"))
        else {
            return;
        };
        let is = |ty: naga::Handle<naga::Type>, n: &str| m.types[ty].name.as_deref() == Some(n);
        let args = &f.arguments;
        let ok = (args.len() == 1 || args.len() == 2 && is(args[1].ty, "LightingParams"))
            && is(args[0].ty, "EnvironmentInput")
            && f.result
                .as_ref()
                .is_some_and(|r| is(r.ty, "LightingOutput"));
        if !ok {
            let sp = self.signature_span(self.span_of(c, m.functions.get_span(h)));
            self.diags.push(
                Diagnostic::error(
                    "`environment` must be `fn environment(in: EnvironmentInput) -> LightingOutput` or `fn environment(in: EnvironmentInput, params: LightingParams) -> LightingOutput`",
                )
                .at(sp, "wrong signature")
                .note("a lighting shader's `environment` replaces the engine's environment term for its materials; rename the function if it is a helper"),
            );
            return;
        }
        out.environment = Some(args.len() == 2);
    }
}

/// `f`'s signature as written, e.g. `fn surface(in: SurfaceInput) -> vec4<f32>`.
fn found_signature(m: &naga::Module, fname: &str, f: &naga::Function) -> String {
    let ctx = m.to_ctx();
    let found_args: Vec<String> = f
        .arguments
        .iter()
        .map(|a| {
            format!(
                "{}: {}",
                a.name.as_deref().unwrap_or("_"),
                ctx.type_to_string(a.ty)
            )
        })
        .collect();
    format!(
        "fn {fname}({}){}",
        found_args.join(", "),
        f.result
            .as_ref()
            .map(|r| format!(" -> {}", ctx.type_to_string(r.ty)))
            .unwrap_or_default()
    )
}
