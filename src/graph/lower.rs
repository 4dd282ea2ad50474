//! Lowering: effect definitions → one petgraph DAG with nested effects expanded
//! under their own namespace (`glow/blurX`), parameters resolved to values,
//! cycles reported, unused passes culled and the passes scheduled.

use super::library::Loader;
use super::*;
use crate::script::ast::{
    self, convert_arg, DefineArg, EffectDef, OutRef, ParamArg, PassKind, Source,
};
use crate::script::parse::{parse_value, RawValue};
use crate::script::types::{ColorSpace, Format, ParamType, Value};
use crate::script::{Diagnostic, Diagnostics, Span, Spanned};
use petgraph::visit::EdgeRef;
use petgraph::Direction;
use std::collections::{BTreeMap, BinaryHeap, HashMap, HashSet};

/// Default pixel format of a pass output when neither the pass nor its effect says.
pub const DEFAULT_FORMAT: Format = Format::Rgba16f;

/// What to compile: a chain of effects applied in order, with `--set` overrides.
#[derive(Debug, Clone, Default)]
pub struct CompileRequest {
    /// Paths to `.fx` files or built-in effect names, applied in order.
    pub effects: Vec<String>,
    pub overrides: Vec<Override>,
    /// Where the scripts come from (None: the built-in library alone, no file
    /// is read; `fxgraph::lookup::DiskEffects` finds files as `fxrun` does).
    pub source: Option<std::sync::Arc<dyn super::EffectSource>>,
}

/// `--set TARGET=VALUE`: TARGET is an effect parameter (`sigma`, `glow.strength`)
/// or a pass parameter (`blurX.radius`, `glow/blurX.radius`).
#[derive(Debug, Clone)]
pub struct Override {
    /// The whole argument, `TARGET=VALUE` (shown in diagnostics).
    pub arg: String,
}

/// A reference to an image during lowering.
#[derive(Debug, Clone, Copy, PartialEq)]
enum SourceRef {
    Input(i32),
    /// A pass output, `back` frames ago.
    Pass(NodeIndex, u32),
    Aux(NodeIndex),
}

pub(super) struct ParsedOverride {
    /// Node path (`glow/blurX`, `glow`) or empty for a bare name.
    pub(super) path: String,
    pub(super) name: String,
    value: Spanned<RawValue>,
    pub(super) key_span: Span,
    used: bool,
    /// Matched an effect parameter: not a pass parameter too (an effect `fog` may
    /// have a pass `fog`).
    effect_param: bool,
}

struct Lowerer<'a> {
    loader: &'a mut Loader,
    diags: &'a mut Diagnostics,
    g: DiGraph<Node, Edge>,
    inputs: BTreeMap<i32, NodeIndex>,
    aux: HashMap<String, NodeIndex>,
    feedback: HashMap<(NodeIndex, u32), NodeIndex>,
    edges: Vec<(SourceRef, NodeIndex, usize, Span)>,
    stack: Vec<String>,
    overrides: Vec<ParsedOverride>,
    params: Vec<EffectParam>,
}

/// Compile a chain of effects into a graph. Returns `None` when there are errors;
/// the diagnostics always come back, with the sources to render them.
pub fn compile(req: &CompileRequest) -> (Option<Graph>, Diagnostics, SourceMap) {
    let r = compile_report(req);
    (r.graph, r.diags, r.sources)
}

/// What [`compile_report`] returns.
pub struct CompileReport {
    /// The graph, when there are no errors.
    pub graph: Option<Graph>,
    pub diags: Diagnostics,
    pub sources: SourceMap,
    /// With errors: the shaders the loaded scripts name, for the shader layer to
    /// check too, so that one run reports script, `--set` and WGSL problems
    /// together. Empty when the graph compiled (its plan names the shaders).
    pub shaders: Vec<super::ShaderReference>,
}

/// [`compile`], and with errors, what can still be checked (see `salvage`).
pub fn compile_report(req: &CompileRequest) -> CompileReport {
    let (graph, diags, sources, loader) = compile_inner(req);
    let shaders = match (&graph, &loader) {
        (None, Some(l)) => super::salvage::shader_references(l),
        _ => Vec::new(),
    };
    CompileReport {
        graph,
        diags,
        sources,
        shaders,
    }
}

type Compiled = (Option<Graph>, Diagnostics, SourceMap, Option<Loader>);

fn compile_inner(req: &CompileRequest) -> Compiled {
    let source = req
        .source
        .clone()
        .unwrap_or_else(|| std::sync::Arc::new(super::Builtins));
    let mut loader = Loader::new(source);
    let mut diags = Diagnostics::default();
    let mut entries = Vec::new();
    for e in &req.effects {
        if let Some(x) = loader.load_entry(e, &mut diags) {
            entries.push(x);
        }
    }
    if diags.has_errors() || entries.is_empty() {
        if entries.is_empty() && !diags.has_errors() {
            diags.push(Diagnostic::error("no effect given"));
        }
        // The `--set` arguments are still checked against what did load.
        let overrides = parse_overrides(&req.overrides, &mut loader, &mut diags);
        if !entries.is_empty() {
            super::salvage::check_overrides(&loader, &overrides, &mut diags);
        }
        diags.sort();
        let sources = loader.sources.clone();
        return (None, diags, sources, Some(loader));
    }
    let overrides = parse_overrides(&req.overrides, &mut loader, &mut diags);
    let mut lw = Lowerer {
        loader: &mut loader,
        diags: &mut diags,
        g: DiGraph::new(),
        inputs: BTreeMap::new(),
        aux: HashMap::new(),
        feedback: HashMap::new(),
        edges: Vec::new(),
        stack: Vec::new(),
        overrides,
        params: Vec::new(),
    };
    let mut current = SourceRef::Input(0);
    let mut namespaces: HashMap<String, usize> = HashMap::new();
    let mut descriptions = Vec::new();
    // IN exists even when no pass reads it (`OUT = IN`, or scales relative to it).
    lw.input_node(0);
    for (_, name) in &entries {
        let at = lw
            .loader
            .effect(name, &mut Diagnostics::default())
            .expect("entry effect is loaded");
        let count = namespaces.entry(name.clone()).or_insert(0);
        *count += 1;
        let ns = if *count == 1 {
            name.clone()
        } else {
            format!("{name}#{count}")
        };
        let def = lw.loader.effect_def(at).clone();
        descriptions.push((ns.clone(), def.description.clone().unwrap_or_default()));
        let args = lw.top_level_args(&def, &ns);
        lw.stack.push(def.name.node.clone());
        if let Some(out) = lw.expand(at, &ns, current, args) {
            current = out;
        }
        lw.stack.pop();
    }
    for o in &lw.overrides {
        if !o.used {
            let what = if o.path.is_empty() {
                o.name.clone()
            } else {
                format!("{}.{}", o.path, o.name)
            };
            let names: Vec<String> = lw.params.iter().map(|p| p.name.clone()).collect();
            let mut d = Diagnostic::error(format!(
                "`--set {what}`: no effect or pass parameter of that name"
            ))
            .at(o.key_span, "unknown parameter");
            if let Some(s) = ast::suggest(&o.name, names.iter().map(|s| s.as_str())) {
                d = d.note(format!("did you mean `{s}`?"));
            } else if !names.is_empty() {
                d = d.note(format!("effect parameters: {}", names.join(", ")));
            }
            lw.diags.push(d);
        }
    }
    let output = lw.g.add_node(Node::Output);
    let out_node = lw.node_of(current);
    lw.g.add_edge(out_node, output, Edge { input: 0 });
    for (src, dst, input, _span) in std::mem::take(&mut lw.edges) {
        let s = lw.node_of(src);
        lw.g.add_edge(s, dst, Edge { input });
    }
    let params = std::mem::take(&mut lw.params);
    let g = std::mem::take(&mut lw.g);
    drop(lw);
    if diags.has_errors() {
        diags.sort();
        let sources = loader.sources.clone();
        return (None, diags, sources, Some(loader));
    }
    let mut graph = Graph {
        graph: g,
        output,
        schedule: Vec::new(),
        params,
        descriptions,
        latency: 0,
        history: 0,
        sources: SourceMap::new(),
    };
    if report_cycles(&graph, &mut diags) {
        diags.sort();
        return (None, diags, loader.sources, None);
    }
    schedule(&mut graph, &mut diags);
    diags.sort();
    graph.sources = loader.sources.clone();
    (Some(graph), diags, loader.sources, None)
}

fn parse_overrides(
    list: &[Override],
    loader: &mut Loader,
    diags: &mut Diagnostics,
) -> Vec<ParsedOverride> {
    let mut out = Vec::new();
    for o in list {
        let file = loader.sources.add("--set", o.arg.clone());
        let Some(eq) = o.arg.find('=') else {
            diags.push(
                Diagnostic::error(format!("`--set {}` needs a value", o.arg))
                    .at(Span::new(file, 0, o.arg.len()), "expected NAME=VALUE"),
            );
            continue;
        };
        let target = &o.arg[..eq];
        let (path, name) = match target.rfind('.') {
            Some(dot) => (target[..dot].to_string(), target[dot + 1..].to_string()),
            None => (String::new(), target.to_string()),
        };
        let key_span = Span::new(file, 0, eq);
        if name.is_empty() {
            diags.push(
                Diagnostic::error("`--set` needs a parameter name").at(key_span, "empty name"),
            );
            continue;
        }
        if let Some(value) = parse_value(file, &o.arg, eq + 1, diags) {
            out.push(ParsedOverride {
                path,
                name,
                value,
                key_span,
                used: false,
                effect_param: false,
            });
        }
    }
    out
}

/// A `--set` value as a parameter argument.
fn raw_to_arg(v: &Spanned<RawValue>) -> Option<Spanned<ParamArg>> {
    let arg = match &v.node {
        RawValue::Number(n) => ParamArg::Literal {
            value: vec![*n],
            is_bool: false,
        },
        RawValue::Tuple(items) => ParamArg::Literal {
            value: items
                .iter()
                .map(|i| match i.node {
                    RawValue::Number(n) => Some(n),
                    _ => None,
                })
                .collect::<Option<Vec<f64>>>()?,
            is_bool: false,
        },
        RawValue::Ref { key, frame: None } if key.is(&["true"]) => ParamArg::Literal {
            value: vec![1.0],
            is_bool: true,
        },
        RawValue::Ref { key, frame: None } if key.is(&["false"]) => ParamArg::Literal {
            value: vec![0.0],
            is_bool: true,
        },
        RawValue::Ref { key, frame: None } if key.parts.len() == 1 => {
            ParamArg::Word(key.first().to_string())
        }
        _ => return None,
    };
    Some(Spanned::new(arg, v.span))
}

impl Lowerer<'_> {
    fn input_node(&mut self, frame: i32) -> NodeIndex {
        if let Some(&n) = self.inputs.get(&frame) {
            return n;
        }
        let n = self.g.add_node(Node::Input { frame });
        self.inputs.insert(frame, n);
        n
    }

    fn node_of(&mut self, r: SourceRef) -> NodeIndex {
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
    fn top_level_args(&mut self, def: &EffectDef, ns: &str) -> HashMap<String, (Value, Span)> {
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
    fn expand(
        &mut self,
        at: (usize, usize),
        ns: &str,
        in_src: SourceRef,
        args: HashMap<String, (Value, Span)>,
    ) -> Option<SourceRef> {
        let def = self.loader.effect_def(at).clone();
        let shader_dir = self.loader.module_dir(at.0);
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

/// Report every dependency cycle (feedback edges excluded). True if any.
fn report_cycles(graph: &Graph, diags: &mut Diagnostics) -> bool {
    let g = &graph.graph;
    let mut found = false;
    for scc in petgraph::algo::tarjan_scc(g) {
        let is_cycle = scc.len() > 1 || g.contains_edge(scc[0], scc[0]);
        if !is_cycle {
            continue;
        }
        found = true;
        let members: HashSet<NodeIndex> = scc.iter().copied().collect();
        // Walk one cycle: from the earliest-declared member, follow edges inside the SCC.
        let start = *scc.iter().min().expect("non-empty");
        let mut path = vec![start];
        let mut seen = HashSet::from([start]);
        let mut cur = start;
        loop {
            let next = g
                .edges_directed(cur, Direction::Outgoing)
                .map(|e| e.target())
                .filter(|t| members.contains(t))
                .min_by_key(|t| if *t == start { 0 } else { t.index() + 1 })
                .expect("a node of a cycle has a successor in it");
            if next == start {
                break;
            }
            if !seen.insert(next) {
                // Trim to the loop that closed.
                let pos = path.iter().position(|&p| p == next).expect("seen");
                path.drain(..pos);
                break;
            }
            path.push(next);
            cur = next;
        }
        let names: Vec<String> = path.iter().map(|&n| graph.pass(n).path.clone()).collect();
        let mut d = Diagnostic::error(format!(
            "dependency cycle: {} → {}",
            names.join(" → "),
            names[0]
        ));
        for (i, &n) in path.iter().enumerate() {
            let next = path[(i + 1) % path.len()];
            // The input of `next` that reads `n`.
            let reader = graph.pass(next);
            let edge = g.edges_connecting(n, next).next().expect("edge in cycle");
            let span = reader
                .inputs
                .get(edge.weight().input)
                .map(|i| i.span)
                .unwrap_or(reader.name_span);
            let label = format!("`{}` reads `{}` here", reader.path, graph.pass(n).path);
            d = if i == 0 {
                d.at(span, label)
            } else {
                d.also(span, label)
            };
        }
        diags.push(d.note("a pass may read an earlier frame of another pass with `PASS.name[-1]` (feedback), which is not a dependency"));
    }
    found
}

/// Cull passes that do not reach the output, warn about them, and order the rest.
fn schedule(graph: &mut Graph, diags: &mut Diagnostics) {
    let g = &graph.graph;
    let mut live = vec![false; g.node_count()];
    let mut stack = vec![graph.output];
    while let Some(n) = stack.pop() {
        if std::mem::replace(&mut live[n.index()], true) {
            continue;
        }
        if let Node::Feedback { pass, .. } = g[n] {
            stack.push(pass);
        }
        stack.extend(g.neighbors_directed(n, Direction::Incoming));
    }
    let mut warned = HashSet::new();
    for n in g.node_indices() {
        if let Node::Pass(p) = &g[n] {
            if !live[n.index()] && warned.insert(p.name_span) {
                diags.push(
                    Diagnostic::warning(format!(
                        "pass `{}` never reaches `OUT`; it is culled",
                        p.path
                    ))
                    .at(p.name_span, "its output is not used"),
                );
            }
        }
    }
    // Kahn's algorithm; among ready passes the earliest declared runs first.
    let mut indeg: HashMap<NodeIndex, usize> = HashMap::new();
    let mut ready = BinaryHeap::new();
    for n in g.node_indices() {
        if !live[n.index()] || !matches!(g[n], Node::Pass(_)) {
            continue;
        }
        let d = g
            .neighbors_directed(n, Direction::Incoming)
            .filter(|s| matches!(g[*s], Node::Pass(_)) && live[s.index()])
            .count();
        indeg.insert(n, d);
        if d == 0 {
            ready.push(std::cmp::Reverse(n));
        }
    }
    let mut order = Vec::new();
    while let Some(std::cmp::Reverse(n)) = ready.pop() {
        order.push(n);
        for m in g.neighbors_directed(n, Direction::Outgoing) {
            if let Some(d) = indeg.get_mut(&m) {
                *d -= 1;
                if *d == 0 {
                    ready.push(std::cmp::Reverse(m));
                }
            }
        }
    }
    let mut latency = 0;
    let mut history = 0;
    for n in g.node_indices() {
        if let Node::Input { frame } = g[n] {
            if live[n.index()] {
                latency = latency.max(frame.max(0) as u32);
                history = history.max((-frame).max(0) as u32);
            }
        }
    }
    graph.schedule = order;
    graph.latency = latency;
    graph.history = history;
}
