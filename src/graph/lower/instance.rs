//! Expanding an effect pass (a nested effect instance): its one `IN`, expanded
//! first when it names another instance; cycles between instances, recursion
//! and the nesting limit reported; the effect looked up and its parameters set.

use super::expand::{Instance, Lowerer, MAX_INSTANCE_DEPTH};
use super::SourceRef;
use crate::script::ast::{
    self, convert_arg, EffectDef, InputDef, ParamArg, PassDef, PassKind, Source,
};
use crate::script::types::Value;
use crate::script::{Diagnostic, Span, Spanned};
use std::collections::HashMap;

impl Lowerer<'_> {
    /// Expand effect pass `pass_name` of `inst` (once; its `IN` first), noting
    /// its handle. `in_progress`: the effect passes being expanded, to find cycles.
    pub(super) fn effect_pass(
        &mut self,
        inst: &Instance,
        pass_name: &str,
        handles: &mut HashMap<String, SourceRef>,
        in_progress: &mut Vec<String>,
    ) -> Option<SourceRef> {
        if let Some(h) = handles.get(pass_name) {
            return Some(*h);
        }
        let p = inst.def.pass(pass_name)?;
        let PassKind::Effect(effect_name) = &p.kind else {
            return None;
        };
        if in_progress.iter().any(|n| n == pass_name) {
            self.report_instance_cycle(inst.def, in_progress, pass_name);
            return None;
        }
        if self.depth >= MAX_INSTANCE_DEPTH {
            self.report_too_deep(effect_name);
            return None;
        }
        self.depth += 1;
        in_progress.push(pass_name.to_string());
        let result = self.instantiate(inst, p, effect_name, handles, in_progress);
        in_progress.pop();
        self.depth -= 1;
        if let Some(r) = result {
            handles.insert(pass_name.to_string(), r);
        }
        result
    }

    /// Effect passes that reach themselves through their `IN`s.
    fn report_instance_cycle(&mut self, def: &EffectDef, in_progress: &[String], pass_name: &str) {
        let mut chain = in_progress.to_vec();
        chain.push(pass_name.to_string());
        let mut d = Diagnostic::error(format!(
            "dependency cycle between effect instances: {}",
            chain.join(" → ")
        ));
        for n in &chain[..chain.len() - 1] {
            if let Some(q) = def.pass(n) {
                d = d.also(q.name.span, format!("`{n}` is part of the cycle"));
            }
        }
        if let Some(l) = d.labels.first_mut() {
            l.primary = true;
        }
        self.diags.push(d);
    }

    /// Instances nested deeper than [`MAX_INSTANCE_DEPTH`] (reported once).
    fn report_too_deep(&mut self, effect_name: &Spanned<String>) {
        if self.too_deep {
            return;
        }
        self.too_deep = true;
        let mut chain: Vec<&str> = self.stack.iter().map(String::as_str).collect();
        if chain.len() > 8 {
            chain.splice(4..chain.len() - 3, ["…"]);
        }
        chain.push(&effect_name.node);
        self.diags.push(
            Diagnostic::error(format!(
                "effect instances are nested more than {MAX_INSTANCE_DEPTH} deep"
            ))
            .at(effect_name.span, format!("level {}", self.depth + 1))
            .note(format!(
                "{}; an instance inside an effect, or whose `IN` is an instance declared after it, is one level deeper",
                chain.join(" → ")
            )),
        );
    }

    /// The instance of effect `effect_name` that pass `p` declares: its `IN`
    /// resolved, the effect found, its arguments set, then expanded.
    fn instantiate(
        &mut self,
        inst: &Instance,
        p: &PassDef,
        effect_name: &Spanned<String>,
        handles: &mut HashMap<String, SourceRef>,
        in_progress: &mut Vec<String>,
    ) -> Option<SourceRef> {
        let in_binding = self.instance_input(p)?;
        // Resolve the IN source, expanding the effect pass it names first.
        if let Source::Pass { name, .. } = &in_binding.source.node {
            if matches!(
                inst.def.pass(&name.node).map(|q| &q.kind),
                Some(PassKind::Effect(_))
            ) {
                self.effect_pass(inst, &name.node, handles, in_progress)?;
            }
        }
        let nested_in = self.resolve_source(&in_binding.source, inst.in_src, handles, inst.def)?;
        if self.stack.contains(&effect_name.node) {
            let mut chain = self.stack.clone();
            chain.push(effect_name.node.clone());
            self.diags.push(
                Diagnostic::error(format!(
                    "effect `{}` instantiates itself: {}",
                    effect_name.node,
                    chain.join(" → ")
                ))
                .at(effect_name.span, "recursive instance"),
            );
            return None;
        }
        let at = self.find_effect(effect_name)?;
        let nested = self.loader.effect_def(at).clone();
        let args = self.instance_args(inst, p, &nested);
        if !p.defines.is_empty() {
            self.diags.push(
                Diagnostic::error("`DEFINE` is set on shader passes, not on effect instances")
                    .at(p.defines[0].name.span, "not allowed here"),
            );
        }
        self.stack.push(effect_name.node.clone());
        let out = self.expand(at, &format!("{}/{}", inst.ns, p.name.node), nested_in, args);
        self.stack.pop();
        out
    }

    /// The one input, `IN`, of effect pass `p`; other inputs are errors.
    fn instance_input<'p>(&mut self, p: &'p PassDef) -> Option<&'p InputDef> {
        let mut in_binding = None;
        for inp in &p.inputs {
            if inp.name.node == "IN" {
                in_binding = Some(inp);
            } else {
                self.diags.push(
                    Diagnostic::error(format!(
                        "an effect instance has one input, `IN`; `{}` is not one",
                        inp.name.node
                    ))
                    .at(inp.name.span, "write `IN = ...`"),
                );
            }
        }
        if in_binding.is_none() {
            self.diags.push(
                Diagnostic::error(format!("effect instance `{}` has no `IN`", p.name.node))
                    .at(p.name.span, "add e.g. `IN = PASS.previous`"),
            );
        }
        in_binding
    }

    /// Where effect `effect_name` is defined, or an error suggesting a known one.
    fn find_effect(&mut self, effect_name: &Spanned<String>) -> Option<(usize, usize)> {
        if let Some(at) = self.loader.effect(&effect_name.node, self.diags) {
            return Some(at);
        }
        let known: Vec<String> = self
            .loader
            .modules
            .iter()
            .flat_map(|(_, m)| m.effects.iter().map(|e| e.name.node.clone()))
            .chain(
                super::super::library::builtin_effects()
                    .into_iter()
                    .map(|(n, _)| n),
            )
            .collect();
        let mut d = Diagnostic::error(format!("unknown effect `{}`", effect_name.node)).at(
            effect_name.span,
            "no effect of this name in this file, its includes or the built-in library",
        );
        if let Some(s) = ast::suggest(&effect_name.node, known.iter().map(|s| s.as_str())) {
            d = d.note(format!("did you mean `{s}`?"));
        }
        self.diags.push(d);
        None
    }

    /// The arguments effect pass `p` gives the nested effect `nested`: its
    /// parameter settings, literal or from `inst`'s values of the same type.
    fn instance_args(
        &mut self,
        inst: &Instance,
        p: &PassDef,
        nested: &EffectDef,
    ) -> HashMap<String, (Value, Span)> {
        let mut args = HashMap::new();
        for s in &p.params {
            let Some(decl) = nested.param(&s.name.node) else {
                let mut d = Diagnostic::error(format!(
                    "effect `{}` has no parameter `{}`",
                    nested.name.node, s.name.node
                ))
                .at(s.name.span, "unknown parameter");
                if let Some(sug) = ast::suggest(
                    &s.name.node,
                    nested.params.iter().map(|q| q.name.node.as_str()),
                ) {
                    d = d.note(format!("did you mean `{sug}`?"));
                }
                self.diags.push(d);
                continue;
            };
            let v = match &s.value.node {
                ParamArg::Param(outer) => match inst.values.get(&outer.node) {
                    Some((v, ty, _)) if *ty == decl.ty => Some(v.clone()),
                    Some((_, ty, _)) => {
                        self.diags.push(
                            Diagnostic::error(format!(
                                "`{}` is {} but `{}` of effect `{}` is {}",
                                outer.node,
                                ty.name(),
                                decl.name.node,
                                nested.name.node,
                                decl.ty.name()
                            ))
                            .at(s.value.span, "type mismatch"),
                        );
                        None
                    }
                    None => None,
                },
                _ => convert_arg(&s.value, &decl.ty, decl.range, &decl.name.node, self.diags),
            };
            if let Some(v) = v {
                args.insert(s.name.node.clone(), (v, s.value.span));
            }
        }
        args
    }
}
