//! Checking a pass against its shader's reflection: every input a texture of the
//! shader and every texture bound, every parameter a field of its uniform struct
//! with a value of the field's type and range; then the pass's uniform layout,
//! each field from a parameter, a standard value or its `@default`.

use super::{
    check_member_value, std_value, Reflection, UniformField, UniformLayout, UniformMember,
    UniformSource, ValueMismatch,
};
use crate::graph::{PassNode, PassParam};
use crate::script::types::format_value;
use crate::script::Diagnostic;

/// Check a pass's inputs and parameters against its shader; build its uniform layout.
/// `shader_name` is how the shader is named in messages.
pub fn bind_pass(
    pass: &PassNode,
    refl: &Reflection,
    shader_name: &str,
) -> Result<UniformLayout, Vec<Diagnostic>> {
    let mut binder = Binder {
        pass,
        refl,
        shader_name,
        input_names: pass.inputs.iter().map(|i| i.name.clone()).collect(),
        members: refl
            .uniform
            .as_ref()
            .map(|u| u.members.as_slice())
            .unwrap_or(&[]),
        diags: Vec::new(),
    };
    binder.check_inputs_are_textures();
    binder.check_textures_are_bound();
    let mut layout = UniformLayout::default();
    if let Some(u) = &refl.uniform {
        layout.size = u.size.max(16);
    }
    for p in &pass.params {
        if let Some(field) = binder.param_field(p) {
            layout.fields.push(field);
        }
    }
    for m in binder.members {
        if layout.fields.iter().any(|f| f.name == m.name)
            || pass.params.iter().any(|p| p.name == m.name)
        {
            continue;
        }
        if let Some(field) = binder.unset_member_field(m) {
            layout.fields.push(field);
        }
    }
    if binder.diags.is_empty() {
        Ok(layout)
    } else {
        Err(binder.diags)
    }
}

/// A pass checked against its shader, and the problems found so far.
struct Binder<'a> {
    pass: &'a PassNode,
    refl: &'a Reflection,
    shader_name: &'a str,
    input_names: Vec<String>,
    /// The members of the shader's uniform struct (none without one).
    members: &'a [UniformMember],
    diags: Vec<Diagnostic>,
}

impl Binder<'_> {
    /// Every input of the pass is a texture the shader declares.
    fn check_inputs_are_textures(&mut self) {
        let refl = self.refl;
        for inp in &self.pass.inputs {
            if !refl.textures.iter().any(|t| t.name == inp.name) {
                let mut d = Diagnostic::error(format!(
                    "shader `{}` has no texture input `{}`",
                    self.shader_name, inp.name
                ))
                .at(inp.span, "not declared by the shader");
                let names: Vec<&str> = refl.textures.iter().map(|t| t.name.as_str()).collect();
                d = match crate::script::ast::suggest(&inp.name, names.iter().copied()) {
                    Some(s) => d.note(format!("did you mean `{s}`?")),
                    None if names.is_empty() => d.note("the shader declares no `texture_2d<f32>`"),
                    None => d.note(format!("its textures: {}", names.join(", "))),
                };
                self.diags.push(d);
            }
        }
    }

    /// Every texture the shader declares is bound by the pass.
    fn check_textures_are_bound(&mut self) {
        let pass = self.pass;
        for t in &self.refl.textures {
            if !pass.inputs.iter().any(|i| i.name == t.name) {
                self.diags.push(
                    Diagnostic::error(format!(
                        "pass `{}` does not bind the shader's texture `{}`",
                        pass.path, t.name
                    ))
                    .at(
                        pass.name_span,
                        format!("add `{} = IN` (or PASS.name, AUX.name)", t.name),
                    )
                    .also(t.span, "declared here"),
                );
            }
        }
    }

    /// The uniform field parameter `p` of the pass sets: a member of the
    /// shader's struct, not a standard value, with a value that fits it.
    fn param_field(&mut self, p: &PassParam) -> Option<UniformField> {
        let Some(m) = self.members.iter().find(|m| m.name == p.name) else {
            self.report_unknown_param(p);
            return None;
        };
        if std_value(&m.name, &self.input_names).is_some() {
            self.diags.push(
                Diagnostic::error(format!(
                    "`{}` is a standard value set by the runtime",
                    p.name
                ))
                .at(p.span, "cannot be set")
                .also(m.span, "declared here"),
            );
            return None;
        }
        match check_member_value(m, &p.value) {
            Ok(()) => Some(m.field(UniformSource::Param(p.value.clone()))),
            Err(ValueMismatch::WrongType { expected, found }) => {
                self.diags.push(
                    Diagnostic::error(format!(
                        "wrong type for `{}`: the shader declares {expected}, found {found}",
                        p.name,
                    ))
                    .at(p.span, format!("expected {expected}"))
                    .also(m.span, "declared here"),
                );
                None
            }
            Err(ValueMismatch::OutOfRange { value, lo, hi }) => {
                self.diags.push(
                    Diagnostic::error(format!(
                        "value {value} of `{}` is out of range [{}, {}]",
                        p.name,
                        format_value(&[lo]),
                        format_value(&[hi])
                    ))
                    .at(p.span, "out of range")
                    .also(m.span, "range declared here"),
                );
                None
            }
        }
    }

    /// A parameter that is no field of the shader's uniform struct.
    fn report_unknown_param(&mut self, p: &PassParam) {
        let mut d = Diagnostic::error(format!(
            "shader `{}` has no parameter `{}`",
            self.shader_name, p.name
        ))
        .at(p.span, "not a field of the shader's uniform struct");
        let names: Vec<&str> = self
            .members
            .iter()
            .filter(|m| std_value(&m.name, &self.input_names).is_none())
            .map(|m| m.name.as_str())
            .collect();
        d = match crate::script::ast::suggest(&p.name, names.iter().copied()) {
            Some(s) => d.note(format!("did you mean `{s}`?")),
            None if names.is_empty() => d.note("the shader takes no parameters"),
            None => d.note(format!("its parameters: {}", names.join(", "))),
        };
        self.diags.push(d);
    }

    /// The field of member `m`, which the pass does not set: a standard value
    /// of the right type, or its `@default` of the right length.
    fn unset_member_field(&mut self, m: &UniformMember) -> Option<UniformField> {
        if let Some((sv, types)) = std_value(&m.name, &self.input_names) {
            if !types.contains(&m.ty) {
                let want: Vec<String> = types.iter().map(|t| t.wgsl()).collect();
                self.diags.push(
                    Diagnostic::error(format!(
                        "standard value `{}` must be declared as {}",
                        m.name,
                        want.join(" or ")
                    ))
                    .at(m.span, "wrong type"),
                );
                return None;
            }
            Some(m.field(UniformSource::Std(sv)))
        } else if let Some(def) = &m.default {
            if def.len() != m.ty.components() {
                self.diags.push(
                    Diagnostic::error(format!(
                        "`@default` of `{}` has {} values, the field has {}",
                        m.name,
                        def.len(),
                        m.ty.components()
                    ))
                    .at(m.span, "wrong default"),
                );
                return None;
            }
            Some(m.field(UniformSource::Param(def.clone())))
        } else {
            self.diags.push(
                Diagnostic::error(format!(
                    "pass `{}` does not set the shader parameter `{}`",
                    self.pass.path, m.name
                ))
                .at(self.pass.name_span, format!("add `{} = ...`", m.name))
                .also(m.span, "declared here without a `// @default(...)`"),
            );
            None
        }
    }
}
