//! Lowering: effect definitions → one petgraph DAG with nested effects expanded
//! under their own namespace (`glow/blurX`), parameters resolved to values,
//! cycles reported, unused passes culled and the passes scheduled.

use super::library::Loader;
use super::overrides::{Override, SetValue};
use super::*;
use crate::script::ast::{
    self, convert_arg, DefineArg, EffectDef, OutRef, ParamArg, PassKind, Source,
};
use crate::script::jitter::JitterPattern;
use crate::script::types::{ColorSpace, Format, ParamType, Value};
use crate::script::{Diagnostic, Diagnostics, Span, Spanned};
use petgraph::visit::EdgeRef;
use petgraph::Direction;
use std::collections::{BTreeMap, BinaryHeap, HashMap, HashSet};

mod expand;
mod instance;
mod order;

use expand::Lowerer;
use order::{report_cycles, schedule};

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
    value: Spanned<Option<SetValue>>,
    pub(super) key_span: Span,
    used: bool,
    /// Matched an effect parameter: not a pass parameter too (an effect `fog` may
    /// have a pass `fog`).
    effect_param: bool,
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
    let entries: Vec<(usize, String)> = req
        .effects
        .iter()
        .filter_map(|e| loader.load_entry(e, &mut diags))
        .collect();
    if diags.has_errors() || entries.is_empty() {
        return not_loaded(req, loader, diags, !entries.is_empty());
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
        depth: 0,
        too_deep: false,
        overrides,
        params: Vec::new(),
        jitter: Vec::new(),
        output: None,
    };
    let (current, descriptions) = lw.expand_entries(&entries);
    lw.report_unused_overrides();
    let output = lw.connect(current);
    let params = std::mem::take(&mut lw.params);
    let jitter_requests = std::mem::take(&mut lw.jitter);
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
        jitter: None,
        sources: SourceMap::new(),
    };
    if report_cycles(&graph, &mut diags) {
        diags.sort();
        return (None, diags, loader.sources, None);
    }
    schedule(&mut graph, &mut diags);
    graph.jitter = scheduled_jitter(&graph, &jitter_requests);
    diags.sort();
    graph.sources = loader.sources.clone();
    (Some(graph), diags, loader.sources, None)
}

/// The result when an effect did not load (or none was given): the `--set`
/// arguments are still checked against what did load.
fn not_loaded(
    req: &CompileRequest,
    mut loader: Loader,
    mut diags: Diagnostics,
    some_loaded: bool,
) -> Compiled {
    if !some_loaded && !diags.has_errors() {
        diags.push(Diagnostic::error("no effect given"));
    }
    let overrides = parse_overrides(&req.overrides, &mut loader, &mut diags);
    if some_loaded {
        super::salvage::check_overrides(&loader, &overrides, &mut diags);
    }
    diags.sort();
    let sources = loader.sources.clone();
    (None, diags, sources, Some(loader))
}

/// An effect's `JITTER` counts when one of its passes runs (not culled).
fn scheduled_jitter(graph: &Graph, requests: &[(String, JitterPattern)]) -> Option<JitterPattern> {
    requests
        .iter()
        .find(|(ns, _)| {
            let prefix = format!("{ns}/");
            graph
                .schedule
                .iter()
                .any(|&n| graph.pass(n).path.starts_with(&prefix))
        })
        .map(|(_, j)| *j)
}

impl Lowerer<'_> {
    /// The effects of the chain expanded in order, each reading the previous
    /// one's output under its own namespace (`name`, `name#2`, ...). Returns
    /// the last output and each instance's description.
    fn expand_entries(
        &mut self,
        entries: &[(usize, String)],
    ) -> (SourceRef, Vec<(String, String)>) {
        let mut current = SourceRef::Input(0);
        let mut namespaces: HashMap<String, usize> = HashMap::new();
        let mut descriptions = Vec::new();
        // IN exists even when no pass reads it (`OUT = IN`, or scales relative to it).
        self.input_node(0);
        for (_, name) in entries {
            let at = self
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
            let def = self.loader.effect_def(at).clone();
            descriptions.push((ns.clone(), def.description.clone().unwrap_or_default()));
            let args = self.top_level_args(&def, &ns);
            self.stack.push(def.name.node.clone());
            if let Some(out) = self.expand(at, &ns, current, args) {
                current = out;
            }
            self.stack.pop();
        }
        (current, descriptions)
    }

    /// A `--set` that matched no effect or pass parameter.
    fn report_unused_overrides(&mut self) {
        for o in &self.overrides {
            if !o.used {
                let what = if o.path.is_empty() {
                    o.name.clone()
                } else {
                    format!("{}.{}", o.path, o.name)
                };
                let names: Vec<String> = self.params.iter().map(|p| p.name.clone()).collect();
                let mut d = Diagnostic::error(format!(
                    "`--set {what}`: no effect or pass parameter of that name"
                ))
                .at(o.key_span, "unknown parameter");
                if let Some(s) = ast::suggest(&o.name, names.iter().map(|s| s.as_str())) {
                    d = d.note(format!("did you mean `{s}`?"));
                } else if !names.is_empty() {
                    d = d.note(format!("effect parameters: {}", names.join(", ")));
                }
                self.diags.push(d);
            }
        }
    }

    /// The output node, reading `current`, and the edges of every pass input.
    fn connect(&mut self, current: SourceRef) -> NodeIndex {
        let output = self.output_node();
        let out_node = self.node_of(current);
        self.g.add_edge(out_node, output, Edge { input: 0 });
        for (src, dst, input, _span) in std::mem::take(&mut self.edges) {
            let s = self.node_of(src);
            self.g.add_edge(s, dst, Edge { input });
        }
        output
    }
}

fn parse_overrides(
    list: &[Override],
    loader: &mut Loader,
    diags: &mut Diagnostics,
) -> Vec<ParsedOverride> {
    let mut out = Vec::new();
    for o in list {
        let file = loader.sources.add("--set", o.arg().to_string());
        match o.in_file(file) {
            Ok(p) => out.push(ParsedOverride {
                path: p.path,
                name: p.name,
                value: p.value,
                key_span: p.key_span,
                used: false,
                effect_param: false,
            }),
            Err(found) => {
                for d in found {
                    diags.push(d);
                }
            }
        }
    }
    out
}

/// A `--set` value as a parameter argument (`None`: no parameter takes it).
fn raw_to_arg(v: &Spanned<Option<SetValue>>) -> Option<Spanned<ParamArg>> {
    let arg = match v.node.as_ref()? {
        SetValue::Numbers(value) => ParamArg::Literal {
            value: value.clone(),
            is_bool: false,
        },
        SetValue::Bool(b) => ParamArg::Literal {
            value: vec![f64::from(u8::from(*b))],
            is_bool: true,
        },
        SetValue::Word(w) => ParamArg::Word(w.clone()),
    };
    Some(Spanned::new(arg, v.span))
}
