//! The resources of a material shader, read from the validated module: where
//! each may be bound, what it is (texture, sampler, the params uniform), and the
//! feature flags its textures give. Part of the [`Checker`]'s reflection.

use super::check::{Checker, Compiled};
use super::{
    MaterialSampler, MaterialShader, MaterialShaderKind, MaterialTexture, FIRST_ENGINE_BINDING,
    MATERIAL_GROUP,
};
use crate::script::{Diagnostic, Span};
use crate::shader::features::{texture_flag, ENGINE_FLAGS};
use naga::common::wgsl::TypeContext as _;
use naga::{ImageClass, ImageDimension, ScalarKind, TypeInner};

/// A global variable with a binding, and where it is declared.
struct Bound<'m> {
    var: &'m naga::GlobalVariable,
    name: String,
    binding: u32,
    span: Span,
}

impl Checker<'_> {
    /// Every bound global variable: a texture, a sampler or the params uniform
    /// of a surface shader, in the bindings allowed to it.
    pub(super) fn reflect_resources(&mut self, c: &Compiled, out: &mut MaterialShader) {
        let m = &c.module;
        let mut bindings: Vec<(u32, Span)> = Vec::new();
        for (h, gv) in m.global_variables.iter() {
            let sp = self.span_of(c, m.global_variables.get_span(h));
            let Some(rb) = &gv.binding else {
                continue;
            };
            let bound = Bound {
                var: gv,
                name: gv.name.clone().unwrap_or_default(),
                binding: rb.binding,
                span: sp,
            };
            if self.check_resource_binding(&bound, rb.group, &bindings) {
                bindings.push((rb.binding, sp));
                self.reflect_resource(m, bound, out);
            }
        }
    }

    /// True when `b` may be bound where it is: not in a lighting shader, in the
    /// material group below the engine's bindings, and on a binding not used yet.
    fn check_resource_binding(&mut self, b: &Bound, group: u32, bindings: &[(u32, Span)]) -> bool {
        let (gname, sp) = (&b.name, b.span);
        if self.kind == MaterialShaderKind::Lighting {
            self.diags.push(
                Diagnostic::error(format!(
                    "a lighting shader declares no resources: `{gname}` is one"
                ))
                .at(sp, "not allowed in a lighting shader")
                .note("lighting shaders run in the deferred light pass, where only the G-buffer exists: take values from `LightingInput` or `LightingParams`"),
            );
            return false;
        }
        if group != MATERIAL_GROUP || b.binding >= FIRST_ENGINE_BINDING {
            self.diags.push(
                Diagnostic::error(format!(
                    "`{gname}` is at @group({}) @binding({}); surface shader resources are in @group(2) with bindings 0 to 15",
                    group, b.binding
                ))
                .at(sp, "bindings 16 and up and other groups are the engine's"),
            );
            return false;
        }
        if let Some((_, first)) = bindings.iter().find(|(n, _)| *n == b.binding) {
            self.diags.push(
                Diagnostic::error(format!("@binding({}) is used twice", b.binding))
                    .at(sp, "second use")
                    .also(*first, "first use"),
            );
            return false;
        }
        true
    }

    /// What `b` is, by its type: a texture, a sampler or the params uniform;
    /// anything else is an error.
    fn reflect_resource(&mut self, m: &naga::Module, b: Bound, out: &mut MaterialShader) {
        let gv = b.var;
        let type_name = |h: naga::Handle<naga::Type>| m.to_ctx().type_to_string(h);
        let (gname, sp) = (b.name, b.span);
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
                    binding: b.binding,
                    srgb,
                    description,
                    span: sp,
                }),
                Err(d) => self.diags.push(d),
            },
            TypeInner::Sampler { comparison: false } => out.samplers.push(MaterialSampler {
                name: gname,
                binding: b.binding,
                span: sp,
            }),
            TypeInner::Struct { .. }
                if gv.space == naga::AddressSpace::Uniform
                    && m.types[gv.ty].name.as_deref() == Some("SurfaceParams") =>
            {
                if let Some(first) = &out.params_var {
                    self.diags.push(
                        Diagnostic::error(format!(
                            "`SurfaceParams` is bound twice (`{first}` and `{gname}`)"
                        ))
                        .at(sp, "second binding"),
                    );
                } else {
                    out.params_var = Some(gname);
                    out.params_binding = Some(b.binding);
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

    /// A surface shader's textures and samplers in binding order, and its
    /// feature flags: the engine's, then one per texture (each its own, none
    /// the engine's); textures need a sampler.
    pub(super) fn reflect_texture_flags(&mut self, out: &mut MaterialShader) {
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
}
