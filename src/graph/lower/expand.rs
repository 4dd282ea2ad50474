//! Expanding effects into graph nodes: top-level parameters and `--set`, nested
//! effect instances under their namespace, shader passes with their inputs, sizes,
//! parameters and defines, and the sources they read.

use super::*;

/// Deepest chain of effect instances expanded: an instance inside an effect's
/// instance inside ..., or an instance whose `IN` is another instance declared
/// after it (expanded first). Expansion is recursive; the limit keeps it far from
/// the stack's end (docs/language.md, "Nesting limit").
pub const MAX_INSTANCE_DEPTH: usize = 64;

pub(super) struct Lowerer<'a> {
    pub(super) loader: &'a mut Loader,
    pub(super) diags: &'a mut Diagnostics,
    pub(super) g: DiGraph<Node, Edge>,
    pub(super) inputs: BTreeMap<i32, NodeIndex>,
    pub(super) aux: HashMap<String, NodeIndex>,
    pub(super) feedback: HashMap<(NodeIndex, u32), NodeIndex>,
    pub(super) edges: Vec<(SourceRef, NodeIndex, usize, Span)>,
    pub(super) stack: Vec<String>,
    /// Effect instances being expanded (nested, or reached through `IN = PASS.x`).
    pub(super) depth: usize,
    /// Whether [`MAX_INSTANCE_DEPTH`] was reported (once per compilation).
    pub(super) too_deep: bool,
    pub(super) overrides: Vec<ParsedOverride>,
    pub(super) params: Vec<EffectParam>,
    /// `JITTER` requests: (namespace of the effect instance, sequence).
    pub(super) jitter: Vec<(String, JitterPattern)>,
}

impl Lowerer<'_> {
    pub(super) fn input_node(&mut self, frame: i32) -> NodeIndex {
        if let Some(&n) = self.inputs.get(&frame) {
            return n;
        }
        let n = self.g.add_node(Node::Input { frame });
        self.inputs.insert(frame, n);
        n
    }

    pub(super) fn node_of(&mut self, r: SourceRef) -> NodeIndex {
        match r {
            SourceRef::Input(f) => self.input_node(f),
            SourceRef::Aux(n) => n,
            SourceRef::Pass(n, 0) => n,
            SourceRef::Pass(n, back) => {
                if let Some(&f) = self.feedback.get(&(n, back)) {
                    return f;
                }
                let f = self.g.add_node(Node::Feedback { pass: n, back });
                self.feedback.insert((n, back), f);
                f
            }
        }
    }

    /// Values of a top-level effect's parameters: defaults, then `--set`.
    pub(super) fn top_level_args(
        &mut self,
        def: &EffectDef,
        ns: &str,
    ) -> HashMap<String, (Value, Span)> {
        let mut args = HashMap::new();
        for decl in &def.params {
            let mut value = decl.default.clone();
            for o in self.overrides.iter_mut() {
                if o.name == decl.name.node && (o.path.is_empty() || o.path == ns) {
                    o.used = true;
                    o.effect_param = true;
                    let Some(arg) = raw_to_arg(&o.value) else {
                        self.diags.push(
                            Diagnostic::error(format!(
                                "`{}` takes a {} value",
                                decl.name.node,
                                decl.ty.name()
                            ))
                            .at(o.value.span, "not a parameter value"),
                        );
                        continue;
                    };
                    if let Some(v) =
                        convert_arg(&arg, &decl.ty, decl.range, &decl.name.node, self.diags)
                    {
                        value = v.clone();
                        args.insert(decl.name.node.clone(), (v, o.value.span));
                    }
                }
            }
            self.params.push(EffectParam {
                effect: ns.to_string(),
                name: decl.name.node.clone(),
                ty: decl.ty.clone(),
                value,
                default: decl.default.clone(),
                range: decl.range,
                description: decl.description.clone(),
            });
        }
        args
    }

    /// Expand one effect instance; returns what its `OUT` refers to.
    pub(super) fn expand(
        &mut self,
        at: (usize, usize),
        ns: &str,
        in_src: SourceRef,
        args: HashMap<String, (Value, Span)>,
    ) -> Option<SourceRef> {
        let def = self.loader.effect_def(at).clone();
        let shader_dir = self.loader.module_dir(at.0);
        if let Some(j) = &def.jitter {
            self.jitter.push((ns.to_string(), j.node));
        }
        // Parameter values of this instance.
        let mut values: HashMap<String, (Value, ParamType, Span)> = HashMap::new();
        for decl in &def.params {
            let (v, span) = args
                .get(&decl.name.node)
                .cloned()
                .unwrap_or((decl.default.clone(), decl.span));
            values.insert(decl.name.node.clone(), (v, decl.ty.clone(), span));
        }
        let effect_in = self.node_of(in_src);
        let effect_colorspace = def
            .colorspace
            .as_ref()
            .map(|c| c.node)
            .unwrap_or(ColorSpace::Linear);
        // Phase 1: a node for every shader pass.
        let mut handles: HashMap<String, SourceRef> = HashMap::new();
        for p in &def.passes {
            if let PassKind::Shader(shader) = &p.kind {
                let format = p
                    .out
                    .format
                    .as_ref()
                    .or(def.format.as_ref())
                    .map(|f| FormatRule::from_spec(f.node, effect_in))
                    .unwrap_or(FormatRule::Fixed(DEFAULT_FORMAT));
                let node = PassNode {
                    path: format!("{ns}/{}", p.name.node),
                    shader: shader.node.clone(),
                    shader_span: shader.span,
                    shader_dir: shader_dir.clone(),
                    inputs: Vec::new(),
                    params: Vec::new(),
                    defines: Vec::new(),
                    size: SizeRule::Scale {
                        sx: 1.0,
                        sy: 1.0,
                        of: effect_in,
                    },
                    format,
                    colorspace: p
                        .out
                        .colorspace
                        .as_ref()
                        .map(|c| c.node)
                        .unwrap_or(effect_colorspace),
                    span: p.span,
                    name_span: p.name.span,
                };
                let n = self.g.add_node(Node::Pass(Box::new(node)));
                handles.insert(p.name.node.clone(), SourceRef::Pass(n, 0));
            }
        }
        // Phase 2: expand effect passes (in declaration order, dependencies first).
        let mut in_progress = Vec::new();
        for p in &def.passes {
            if matches!(p.kind, PassKind::Effect(_)) {
                self.effect_pass(
                    &def,
                    &p.name.node,
                    ns,
                    in_src,
                    &values,
                    &mut handles,
                    &mut in_progress,
                );
            }
        }
        // Phase 3: inputs, sizes, parameters and defines of the shader passes.
        for p in &def.passes {
            let PassKind::Shader(_) = &p.kind else {
                continue;
            };
            let Some(SourceRef::Pass(node, 0)) = handles.get(&p.name.node).copied() else {
                continue;
            };
            let mut inputs = Vec::new();
            let mut input_refs = HashMap::new();
            for (i, inp) in p.inputs.iter().enumerate() {
                let Some(r) = self.resolve_source(&inp.source, in_src, &handles, &def) else {
                    continue;
                };
                input_refs.insert(inp.name.node.clone(), r);
                self.edges.push((r, node, i, inp.source.span));
                inputs.push(PassInput {
                    name: inp.name.node.clone(),
                    sampling: inp.sampling(),
                    colorspace: inp
                        .colorspace
                        .as_ref()
                        .map(|c| c.node)
                        .unwrap_or(effect_colorspace),
                    span: inp.name.span.to(inp.source.span),
                });
            }
            let size = match (&p.out.size, &p.out.scale) {
                (Some(s), _) => SizeRule::Absolute(s.node.0, s.node.1),
                (None, scale) => {
                    let (sx, sy) = scale.as_ref().map(|s| s.node).unwrap_or((1.0, 1.0));
                    let of = match &p.out.relative_to {
                        Some(rel) => match input_refs.get(&rel.node) {
                            Some(r) => self.node_of(*r),
                            None => effect_in,
                        },
                        None => effect_in,
                    };
                    SizeRule::Scale { sx, sy, of }
                }
            };
            let path = format!("{ns}/{}", p.name.node);
            let mut params = Vec::new();
            for s in &p.params {
                let (value, is_bool) = match &s.value.node {
                    ParamArg::Literal { value, is_bool } => (value.clone(), *is_bool),
                    ParamArg::Param(name) => match values.get(&name.node) {
                        Some((v, ty, _)) => (v.clone(), *ty == ParamType::Bool),
                        None => continue,
                    },
                    ParamArg::Word(w) => {
                        self.diags.push(
                            Diagnostic::error(format!("`{w}` is not an input or a value"))
                                .at(s.value.span, "a shader parameter takes a number, a tuple, true/false or PARAM.name")
                                .note("inputs are written IN, PASS.name or AUX.name"),
                        );
                        continue;
                    }
                };
                params.push(PassParam {
                    name: s.name.node.clone(),
                    value,
                    is_bool,
                    span: s.value.span,
                });
            }
            // `--set pass.name=value`
            for o in self.overrides.iter_mut() {
                let matches_path = !o.effect_param
                    && !o.path.is_empty()
                    && (o.path == path || o.path == p.name.node);
                if !matches_path {
                    continue;
                }
                o.used = true;
                let Some(arg) = raw_to_arg(&o.value) else {
                    self.diags.push(
                        Diagnostic::error("not a parameter value")
                            .at(o.value.span, "expected a number, tuple or true/false"),
                    );
                    continue;
                };
                let ParamArg::Literal { value, is_bool } = arg.node else {
                    self.diags.push(
                        Diagnostic::error("a shader parameter takes numbers")
                            .at(o.value.span, "expected a number, tuple or true/false"),
                    );
                    continue;
                };
                match params.iter_mut().find(|q| q.name == o.name) {
                    Some(q) => {
                        q.value = value;
                        q.is_bool = is_bool;
                        q.span = o.value.span;
                    }
                    None => params.push(PassParam {
                        name: o.name.clone(),
                        value,
                        is_bool,
                        span: o.value.span,
                    }),
                }
            }
            let mut defines = Vec::new();
            for d in &p.defines {
                let v = match &d.value.node {
                    DefineArg::Int(i) => *i,
                    DefineArg::Param(name) => match values.get(&name.node) {
                        Some((v, ty, _))
                            if v.len() == 1
                                && v[0].fract() == 0.0
                                && !matches!(ty, ParamType::Float) =>
                        {
                            v[0] as i64
                        }
                        Some((_, ty, _)) => {
                            self.diags.push(
                                Diagnostic::error(format!(
                                    "`DEFINE.{}` needs a whole number, but `{}` is {}",
                                    d.name.node,
                                    name.node,
                                    ty.name()
                                ))
                                .at(d.value.span, "use an INT, BOOL or ENUM parameter"),
                            );
                            continue;
                        }
                        None => continue,
                    },
                };
                defines.push((d.name.node.clone(), v));
            }
            defines.sort();
            if let Node::Pass(pn) = &mut self.g[node] {
                pn.inputs = inputs;
                pn.size = size;
                pn.params = params;
                pn.defines = defines;
            }
        }
        match &def.out {
            Some(OutRef::In(_)) => Some(in_src),
            Some(OutRef::Pass(name)) => handles.get(&name.node).copied(),
            None => None,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn effect_pass(
        &mut self,
        def: &EffectDef,
        pass_name: &str,
        ns: &str,
        in_src: SourceRef,
        values: &HashMap<String, (Value, ParamType, Span)>,
        handles: &mut HashMap<String, SourceRef>,
        in_progress: &mut Vec<String>,
    ) -> Option<SourceRef> {
        if let Some(h) = handles.get(pass_name) {
            return Some(*h);
        }
        let p = def.pass(pass_name)?;
        let PassKind::Effect(effect_name) = &p.kind else {
            return None;
        };
        if in_progress.iter().any(|n| n == pass_name) {
            let mut chain = in_progress.clone();
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
            return None;
        }
        if self.depth >= MAX_INSTANCE_DEPTH {
            if !self.too_deep {
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
            return None;
        }
        self.depth += 1;
        in_progress.push(pass_name.to_string());
        let result = (|| {
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
            let Some(in_binding) = in_binding else {
                self.diags.push(
                    Diagnostic::error(format!("effect instance `{pass_name}` has no `IN`"))
                        .at(p.name.span, "add e.g. `IN = PASS.previous`"),
                );
                return None;
            };
            // Resolve the IN source, expanding the effect pass it names first.
            if let Source::Pass { name, .. } = &in_binding.source.node {
                if matches!(
                    def.pass(&name.node).map(|q| &q.kind),
                    Some(PassKind::Effect(_))
                ) {
                    self.effect_pass(def, &name.node, ns, in_src, values, handles, in_progress)?;
                }
            }
            let nested_in = self.resolve_source(&in_binding.source, in_src, handles, def)?;
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
            let Some(at) = self.loader.effect(&effect_name.node, self.diags) else {
                let known: Vec<String> = self
                    .loader
                    .modules
                    .iter()
                    .flat_map(|(_, m)| m.effects.iter().map(|e| e.name.node.clone()))
                    .chain(
                        super::library::builtin_effects()
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
                return None;
            };
            let nested = self.loader.effect_def(at).clone();
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
                    ParamArg::Param(outer) => match values.get(&outer.node) {
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
            if !p.defines.is_empty() {
                self.diags.push(
                    Diagnostic::error("`DEFINE` is set on shader passes, not on effect instances")
                        .at(p.defines[0].name.span, "not allowed here"),
                );
            }
            self.stack.push(effect_name.node.clone());
            let out = self.expand(at, &format!("{ns}/{pass_name}"), nested_in, args);
            self.stack.pop();
            out
        })();
        in_progress.pop();
        self.depth -= 1;
        if let Some(r) = result {
            handles.insert(pass_name.to_string(), r);
        }
        result
    }

    fn resolve_source(
        &mut self,
        source: &Spanned<Source>,
        in_src: SourceRef,
        handles: &HashMap<String, SourceRef>,
        def: &EffectDef,
    ) -> Option<SourceRef> {
        let shift = |r: SourceRef, frame: i32, diags: &mut Diagnostics| -> Option<SourceRef> {
            match r {
                SourceRef::Input(f) => Some(SourceRef::Input(f + frame)),
                SourceRef::Pass(n, back) => {
                    if frame > 0 {
                        diags.push(
                            Diagnostic::error("a later frame of a pass output is not available")
                                .at(
                                source.span,
                                "this effect's input is a pass output, which has no later frames",
                            ),
                        );
                        None
                    } else {
                        Some(SourceRef::Pass(n, back + (-frame) as u32))
                    }
                }
                SourceRef::Aux(_) if frame != 0 => {
                    diags.push(
                        Diagnostic::error("auxiliary scene inputs have no earlier or later frames")
                            .at(source.span, "this effect's input is an auxiliary image"),
                    );
                    None
                }
                aux => Some(aux),
            }
        };
        match &source.node {
            Source::In { frame } => shift(in_src, *frame, self.diags),
            Source::Pass { name, frame } => {
                let h = *handles.get(&name.node)?;
                def.pass(&name.node)?;
                shift(h, *frame, self.diags)
            }
            Source::Aux { name } => {
                if let Some(&n) = self.aux.get(&name.node) {
                    return Some(SourceRef::Aux(n));
                }
                let n = self.g.add_node(Node::Aux {
                    name: name.node.clone(),
                    span: name.span,
                });
                self.aux.insert(name.node.clone(), n);
                Some(SourceRef::Aux(n))
            }
        }
    }
}
