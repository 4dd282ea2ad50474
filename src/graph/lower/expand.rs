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
    /// The graph's output, made when a pass first scales from it (`VIEWPORT`)
    /// or when the graph is connected.
    pub(super) output: Option<NodeIndex>,
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

    /// The graph's output node (`VIEWPORT` in a size rule).
    pub(super) fn output_node(&mut self) -> NodeIndex {
        match self.output {
            Some(n) => n,
            None => *self.output.insert(self.g.add_node(Node::Output)),
        }
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
                step: decl.step,
                description: decl.description.clone(),
            });
        }
        args
    }
}

/// One effect instance being expanded: its definition, namespace, input and
/// parameter values.
pub(super) struct Instance<'d> {
    pub(super) def: &'d EffectDef,
    pub(super) ns: &'d str,
    pub(super) in_src: SourceRef,
    /// Parameter values of this instance: value, type, and where it was set.
    pub(super) values: HashMap<String, (Value, ParamType, Span)>,
    /// The node the effect's `IN` is.
    effect_in: NodeIndex,
    /// The colour space of the effect's passes and inputs where they name none.
    colorspace: ColorSpace,
}

/// Parameter values of an instance of `def`: `args` where given, else the defaults.
fn instance_values(
    def: &EffectDef,
    args: &HashMap<String, (Value, Span)>,
) -> HashMap<String, (Value, ParamType, Span)> {
    let mut values = HashMap::new();
    for decl in &def.params {
        let (v, span) = args
            .get(&decl.name.node)
            .cloned()
            .unwrap_or((decl.default.clone(), decl.span));
        values.insert(decl.name.node.clone(), (v, decl.ty.clone(), span));
    }
    values
}

impl Lowerer<'_> {
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
        let values = instance_values(&def, &args);
        let inst = Instance {
            def: &def,
            ns,
            in_src,
            values,
            effect_in: self.node_of(in_src),
            colorspace: def
                .colorspace
                .as_ref()
                .map(|c| c.node)
                .unwrap_or(ColorSpace::Linear),
        };
        let mut handles = self.add_shader_pass_nodes(&inst, shader_dir);
        // Effect passes, in declaration order, dependencies first.
        let mut in_progress = Vec::new();
        for p in &def.passes {
            if matches!(p.kind, PassKind::Effect(_)) {
                self.effect_pass(&inst, &p.name.node, &mut handles, &mut in_progress);
            }
        }
        for p in &def.passes {
            self.complete_shader_pass(&inst, p, &handles);
        }
        match &def.out {
            Some(OutRef::In(_)) => Some(in_src),
            Some(OutRef::Pass(name)) => handles.get(&name.node).copied(),
            None => None,
        }
    }

    /// A node for every shader pass of the instance (inputs, size, parameters
    /// and defines come later); the handles of the passes by name.
    fn add_shader_pass_nodes(
        &mut self,
        inst: &Instance,
        shader_dir: Option<std::path::PathBuf>,
    ) -> HashMap<String, SourceRef> {
        let mut handles = HashMap::new();
        for p in &inst.def.passes {
            if let PassKind::Shader(shader) = &p.kind {
                let format = p
                    .out
                    .format
                    .as_ref()
                    .or(inst.def.format.as_ref())
                    .map(|f| FormatRule::from_spec(f.node, inst.effect_in))
                    .unwrap_or(FormatRule::Fixed(DEFAULT_FORMAT));
                let node = PassNode {
                    path: format!("{}/{}", inst.ns, p.name.node),
                    shader: shader.node.clone(),
                    shader_span: shader.span,
                    shader_dir: shader_dir.clone(),
                    inputs: Vec::new(),
                    params: Vec::new(),
                    defines: Vec::new(),
                    size: SizeRule::scale(1.0, 1.0, inst.effect_in),
                    format,
                    colorspace: p
                        .out
                        .colorspace
                        .as_ref()
                        .map(|c| c.node)
                        .unwrap_or(inst.colorspace),
                    span: p.span,
                    name_span: p.name.span,
                };
                let n = self.g.add_node(Node::Pass(Box::new(node)));
                handles.insert(p.name.node.clone(), SourceRef::Pass(n, 0));
            }
        }
        handles
    }

    /// Inputs, size, parameters and defines of shader pass `p`, once every pass
    /// of the instance has a handle.
    fn complete_shader_pass(
        &mut self,
        inst: &Instance,
        p: &ast::PassDef,
        handles: &HashMap<String, SourceRef>,
    ) {
        let PassKind::Shader(_) = &p.kind else {
            return;
        };
        let Some(SourceRef::Pass(node, 0)) = handles.get(&p.name.node).copied() else {
            return;
        };
        let (inputs, input_refs) = self.shader_pass_inputs(inst, p, node, handles);
        let size = self.shader_pass_size(inst, p, &input_refs);
        let mut params = self.shader_pass_params(inst, p);
        self.apply_pass_overrides(&format!("{}/{}", inst.ns, p.name.node), p, &mut params);
        let defines = self.shader_pass_defines(inst, p);
        if let Node::Pass(pn) = &mut self.g[node] {
            pn.inputs = inputs;
            pn.size = size;
            pn.params = params;
            pn.defines = defines;
        }
    }

    /// The inputs of shader pass `p` (node `node`), each with an edge from its
    /// source, and the source each input name refers to.
    fn shader_pass_inputs(
        &mut self,
        inst: &Instance,
        p: &ast::PassDef,
        node: NodeIndex,
        handles: &HashMap<String, SourceRef>,
    ) -> (Vec<PassInput>, HashMap<String, SourceRef>) {
        let mut inputs = Vec::new();
        let mut input_refs = HashMap::new();
        for (i, inp) in p.inputs.iter().enumerate() {
            let Some(r) = self.resolve_source(&inp.source, inst.in_src, handles, inst.def) else {
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
                    .unwrap_or(inst.colorspace),
                span: inp.name.span.to(inp.source.span),
            });
        }
        (inputs, input_refs)
    }

    /// The size of shader pass `p`, axis by axis: pixels (`OUT.SIZE`,
    /// `OUT.WIDTH`, `OUT.HEIGHT`), or scaled from the image `OUT.RELATIVE_TO`
    /// names for that axis: the effect's input by default, one of the pass's
    /// inputs, or `VIEWPORT`, the run's output size.
    fn shader_pass_size(
        &mut self,
        inst: &Instance,
        p: &ast::PassDef,
        input_refs: &HashMap<String, SourceRef>,
    ) -> SizeRule {
        let out = &p.out;
        let fixed = |i: usize| match (&out.size, &out.width, &out.height) {
            (Some(s), _, _) => Some(if i == 0 { s.node.0 } else { s.node.1 }),
            (None, w, h) => if i == 0 { w } else { h }.as_ref().map(|v| v.node),
        };
        let (sx, sy) = out.scale.as_ref().map(|s| s.node).unwrap_or((1.0, 1.0));
        let (rx, ry) = match &out.relative_to {
            Some(rel) => (rel.node.0.clone(), rel.node.1.clone()),
            None => ("IN".to_string(), "IN".to_string()),
        };
        let mut axis = |pixels: Option<u32>, factor: f64, of: &str| match pixels {
            Some(n) => AxisSize::Pixels(n),
            None => AxisSize::Scale(factor, self.relative_node(inst, input_refs, of)),
        };
        SizeRule {
            x: axis(fixed(0), sx, &rx),
            y: axis(fixed(1), sy, &ry),
        }
    }

    /// The node `OUT.RELATIVE_TO` names: a pass input, `VIEWPORT` (the graph's
    /// output), or the effect's input (`IN`, and names the check rejected).
    fn relative_node(
        &mut self,
        inst: &Instance,
        input_refs: &HashMap<String, SourceRef>,
        name: &str,
    ) -> NodeIndex {
        match input_refs.get(name) {
            Some(r) if name != "IN" => self.node_of(*r),
            _ if name == ast::VIEWPORT => self.output_node(),
            _ => inst.effect_in,
        }
    }

    /// The parameters shader pass `p` sets: literals, or the instance's values.
    fn shader_pass_params(&mut self, inst: &Instance, p: &ast::PassDef) -> Vec<PassParam> {
        let mut params = Vec::new();
        for s in &p.params {
            let (value, is_bool) = match &s.value.node {
                ParamArg::Literal { value, is_bool } => (value.clone(), *is_bool),
                ParamArg::Param(name) => match inst.values.get(&name.node) {
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
        params
    }

    /// `--set pass.name=value` for shader pass `p` at `path`: replaces or adds
    /// to `params`.
    fn apply_pass_overrides(&mut self, path: &str, p: &ast::PassDef, params: &mut Vec<PassParam>) {
        for o in self.overrides.iter_mut() {
            let matches_path =
                !o.effect_param && !o.path.is_empty() && (o.path == path || o.path == p.name.node);
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
    }

    /// The `DEFINE`s of shader pass `p`, sorted: whole numbers, or the
    /// instance's whole-number parameters.
    fn shader_pass_defines(&mut self, inst: &Instance, p: &ast::PassDef) -> Vec<(String, i64)> {
        let mut defines = Vec::new();
        for d in &p.defines {
            let v = match &d.value.node {
                DefineArg::Int(i) => *i,
                DefineArg::Param(name) => match inst.values.get(&name.node) {
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
        defines
    }

    /// What `source` refers to in an instance whose `IN` is `in_src`.
    pub(super) fn resolve_source(
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
