//! The filter graph: lowering effect scripts to a petgraph DAG, resolving sizes and
//! formats, scheduling, and planning texture lifetimes. Plain data, no GPU.

pub mod dot;
pub mod library;
mod lower;
mod overrides;
pub mod plan;
mod salvage;
pub mod source;

pub use lower::{compile, compile_report, CompileReport, CompileRequest};
pub use overrides::{Override, SetValue};
pub use plan::{InputDesc, Plan, PlanOptions, ReusePolicy, Step};
pub use salvage::ShaderReference;
pub use source::{Builtins, EffectSource};

use crate::script::ast::FormatSpec;
use crate::script::types::{ColorSpace, ParamType, Sampling, Value};
use crate::script::{SourceMap, Span};
use petgraph::graph::{DiGraph, NodeIndex};
use std::path::PathBuf;

/// A node of the filter graph.
#[derive(Debug, Clone)]
pub enum Node {
    /// The effect input, `frame` frames from the current one (`IN[-1]` is -1).
    Input { frame: i32 },
    /// An auxiliary scene image (G-buffer) or user-supplied image.
    Aux { name: String, span: Span },
    /// A shader pass.
    Pass(Box<PassNode>),
    /// The output of `pass`, `back` frames ago (feedback / pass history).
    /// Not a dependency: it reads what an earlier frame stored.
    Feedback { pass: NodeIndex, back: u32 },
    /// The graph result.
    Output,
}

/// Edge from a source node to the pass that reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// Index into the reading pass's `inputs`, or 0 for the output edge.
    pub input: usize,
}

/// A shader pass after lowering (namespaced, parameters resolved to values).
#[derive(Debug, Clone)]
pub struct PassNode {
    /// Namespaced path, e.g. `glow/blurX`.
    pub path: String,
    /// Shader name (`SHADER.<name>`), looked up as `<name>.wgsl`.
    pub shader: String,
    pub shader_span: Span,
    /// Folder of the `.fx` file that named the shader, searched first.
    pub shader_dir: Option<PathBuf>,
    pub inputs: Vec<PassInput>,
    pub params: Vec<PassParam>,
    /// `DEFINE.NAME = n`, sorted by name.
    pub defines: Vec<(String, i64)>,
    pub size: SizeRule,
    pub format: FormatRule,
    pub colorspace: ColorSpace,
    pub span: Span,
    pub name_span: Span,
}

#[derive(Debug, Clone)]
pub struct PassInput {
    /// The binding name (the shader's `texture_2d` global).
    pub name: String,
    pub sampling: Sampling,
    /// The colour space the shader expects.
    pub colorspace: ColorSpace,
    pub span: Span,
}

#[derive(Debug, Clone)]
pub struct PassParam {
    pub name: String,
    pub value: Value,
    pub is_bool: bool,
    /// Where the value was written (pass binding, effect parameter or `--set`).
    pub span: Span,
}

/// How big a pass output is: each axis in pixels or scaled from a node.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeRule {
    pub x: AxisSize,
    pub y: AxisSize,
}

/// One axis of a pass's size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisSize {
    /// So many pixels (`OUT.SIZE`, `OUT.WIDTH`, `OUT.HEIGHT`).
    Pixels(u32),
    /// A factor of the same axis of a node: the effect input, one of the pass's
    /// inputs, or the graph's output (`VIEWPORT`: the size the run asks for).
    Scale(f64, NodeIndex),
}

impl SizeRule {
    /// `w` x `h` pixels.
    pub fn absolute(w: u32, h: u32) -> Self {
        SizeRule {
            x: AxisSize::Pixels(w),
            y: AxisSize::Pixels(h),
        }
    }

    /// `sx` times the width and `sy` times the height of `of`.
    pub fn scale(sx: f64, sy: f64, of: NodeIndex) -> Self {
        SizeRule {
            x: AxisSize::Scale(sx, of),
            y: AxisSize::Scale(sy, of),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum FormatRule {
    Fixed(crate::script::types::Format),
    /// The format of this node (the effect input).
    SameAs(NodeIndex),
}

impl FormatRule {
    pub(crate) fn from_spec(spec: FormatSpec, effect_in: NodeIndex) -> Self {
        match spec {
            FormatSpec::Fixed(f) => FormatRule::Fixed(f),
            FormatSpec::SameAsInput => FormatRule::SameAs(effect_in),
        }
    }
}

/// A parameter of a top-level effect, with its current value (for `--describe`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct EffectParam {
    pub effect: String,
    pub name: String,
    pub ty: ParamType,
    pub value: Value,
    pub default: Value,
    pub range: Option<(f64, f64)>,
    /// `STEP`: a control's increment.
    pub step: Option<f64>,
    pub description: String,
}

/// A compiled filter graph.
#[derive(Debug)]
pub struct Graph {
    pub graph: DiGraph<Node, Edge>,
    pub output: NodeIndex,
    /// Passes in execution order (topological, ties by declaration), culled.
    pub schedule: Vec<NodeIndex>,
    pub params: Vec<EffectParam>,
    /// Descriptions of the top-level effects.
    pub descriptions: Vec<(String, String)>,
    /// Frames of input needed after the current one (`IN[+n]`): the graph's latency.
    pub latency: u32,
    /// Frames of input needed before the current one (`IN[-n]`).
    pub history: u32,
    /// The sub-pixel jitter an effect of the graph asks its input frames to be
    /// rendered with (`JITTER = halton23`), `None` when no effect whose passes run
    /// asks for one. The frame source applies [`crate::script::JitterPattern::offset`] of the frame
    /// index and gives it with the frame (`FrameInputs::jitter`).
    pub jitter: Option<crate::script::JitterPattern>,
    /// Sources (scripts) the diagnostics refer to.
    pub sources: SourceMap,
}

impl Graph {
    pub fn pass(&self, n: NodeIndex) -> &PassNode {
        match &self.graph[n] {
            Node::Pass(p) => p,
            other => panic!("node {n:?} is not a pass: {other:?}"),
        }
    }

    /// The node feeding input `i` of pass `n`.
    pub fn input_source(&self, n: NodeIndex, i: usize) -> NodeIndex {
        self.graph
            .edges_directed(n, petgraph::Direction::Incoming)
            .find(|e| e.weight().input == i)
            .map(|e| petgraph::visit::EdgeRef::source(&e))
            .expect("every pass input has an edge")
    }

    /// The inputs of pass `n`, each with the node feeding it.
    pub fn inputs_with_sources(
        &self,
        n: NodeIndex,
    ) -> impl Iterator<Item = (&PassInput, NodeIndex)> + '_ {
        let p = self.pass(n);
        p.inputs
            .iter()
            .enumerate()
            .map(move |(i, inp)| (inp, self.input_source(n, i)))
    }

    /// The node feeding the output.
    pub fn output_source(&self) -> NodeIndex {
        self.graph
            .neighbors_directed(self.output, petgraph::Direction::Incoming)
            .next()
            .expect("output has a source")
    }

    /// True if any pass uses feedback (its result depends on earlier output frames).
    pub fn has_feedback(&self) -> bool {
        self.graph
            .node_weights()
            .any(|n| matches!(n, Node::Feedback { .. }))
    }

    /// Names of the auxiliary inputs the graph reads.
    pub fn aux_inputs(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .graph
            .node_weights()
            .filter_map(|n| match n {
                Node::Aux { name, .. } => Some(name.clone()),
                _ => None,
            })
            .collect();
        v.sort();
        v.dedup();
        v
    }

    /// A short label for a node (pass path, `IN[-1]`, `AUX.depth`, ...).
    /// Whether a pass scales an axis from the graph's output (`VIEWPORT`).
    pub fn scales_from_viewport(&self) -> bool {
        self.schedule.iter().any(|&n| match &self.graph[n] {
            Node::Pass(p) => [p.size.x, p.size.y]
                .iter()
                .any(|a| matches!(a, AxisSize::Scale(_, of) if *of == self.output)),
            _ => false,
        })
    }

    pub fn label(&self, n: NodeIndex) -> String {
        match &self.graph[n] {
            Node::Input { frame: 0 } => "IN".into(),
            Node::Input { frame } => format!("IN[{frame:+}]"),
            Node::Aux { name, .. } => format!("AUX.{name}"),
            Node::Pass(p) => p.path.clone(),
            Node::Feedback { pass, back } => format!("{}[-{back}]", self.pass(*pass).path),
            Node::Output => "OUT".into(),
        }
    }
}
