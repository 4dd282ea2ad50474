//! Reading a validated material shader: its `surface` / `lighting` function's
//! signature, its resources (textures, samplers, the params uniform) and binding
//! rules, the annotated params struct, and the feature flags it has. The second
//! half of the [`Checker`].

use super::check::{Checker, Compiled};
use super::{
    MaterialParams, MaterialSampler, MaterialShader, MaterialShaderKind, MaterialTexture,
    FIRST_ENGINE_BINDING, MATERIAL_GROUP,
};
use crate::script::{Diagnostic, Span};
use crate::shader::features::{texture_flag, ENGINE_FLAGS};
use crate::shader::include::Assembly;
use crate::shader::reflect::{member_annotations, UniformMember};
use naga::common::wgsl::TypeContext as _;
use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};

impl Checker<'_> {
    pub(super) fn reflect(
        &mut self,
        name: &str,
        shown: &str,
        c: &Compiled,
    ) -> Option<MaterialShader> {
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
            environment: None,
        };
        // The function.
        let fname = kind.name();
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
        if kind == MaterialShaderKind::Lighting {
            self.reflect_environment(c, &mut out);
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
