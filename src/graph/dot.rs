//! Graphviz DOT output of a compiled graph.

use super::plan::Plan;
use super::{Graph, Node, PassNode};
use petgraph::graph::NodeIndex;
use petgraph::visit::EdgeRef;
use std::fmt::Write as _;

fn esc(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

/// DOT text: one box per pass with its size, format and colour space (from `plan`
/// when given, else the rules), solid data edges and dashed feedback edges.
pub fn to_dot(graph: &Graph, plan: Option<&Plan>) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph fxgraph {{");
    let _ = writeln!(out, "  rankdir=LR;");
    let _ = writeln!(out, "  node [fontname=\"Helvetica\", fontsize=10];");
    write_nodes(&mut out, graph, plan);
    write_edges(&mut out, graph);
    let _ = writeln!(out, "}}");
    out
}

/// Inputs as ellipses, the output as a double circle, passes as boxes (dashed
/// when culled); feedback nodes are drawn as edges.
fn write_nodes(out: &mut String, graph: &Graph, plan: Option<&Plan>) {
    let g = &graph.graph;
    for n in g.node_indices() {
        let id = n.index();
        match &g[n] {
            Node::Input { .. } | Node::Aux { .. } => {
                let _ = writeln!(
                    out,
                    "  n{id} [label=\"{}\", shape=ellipse, style=filled, fillcolor=\"#e8f0ff\"];",
                    esc(&graph.label(n))
                );
            }
            Node::Output => {
                let _ = writeln!(out, "  n{id} [label=\"OUT\", shape=doublecircle];");
            }
            Node::Feedback { .. } => {}
            Node::Pass(p) => {
                let live = graph.schedule.contains(&n);
                let detail =
                    match plan.and_then(|pl| pl.passes.iter().find(|pp| pp.node == Some(n))) {
                        Some(pp) => format!(
                            "{}x{} {} {}",
                            pp.desc.width, pp.desc.height, pp.desc.format, pp.colorspace
                        ),
                        None => rule_detail(graph, p),
                    };
                let style = if live { "filled" } else { "dashed" };
                let _ = writeln!(
                    out,
                    "  n{id} [label=\"{}\\nSHADER.{}\\n{}\", shape=box, style={style}, fillcolor=\"#fff6dd\"];",
                    esc(&p.path),
                    esc(&p.shader),
                    esc(&detail)
                );
            }
        }
    }
}

/// A pass's size rule in words: `640x480`, `2x2 of IN`, or one axis at a time.
fn size_detail(graph: &Graph, size: &super::SizeRule) -> String {
    use super::AxisSize::{Pixels, Scale};
    match (size.x, size.y) {
        (Pixels(w), Pixels(h)) => format!("{w}x{h}"),
        (Scale(sx, a), Scale(sy, b)) if a == b => format!("{sx}x{sy} of {}", name(graph, a)),
        (x, y) => {
            let axis = |a: super::AxisSize, what: &str| match a {
                Pixels(n) => format!("{n} px"),
                Scale(s, of) => format!("{s} of {}'s {what}", name(graph, of)),
            };
            format!("{} x {}", axis(x, "width"), axis(y, "height"))
        }
    }
}

/// The name a size rule gives a node: the graph's output is `VIEWPORT` there.
fn name(graph: &Graph, n: NodeIndex) -> String {
    match graph.graph[n] {
        Node::Output => "VIEWPORT".into(),
        _ => graph.label(n),
    }
}

/// A pass's size, format and colour space as its rules say (without a plan).
fn rule_detail(graph: &Graph, p: &PassNode) -> String {
    let size = size_detail(graph, &p.size);
    let format = match &p.format {
        super::FormatRule::Fixed(f) => f.name().to_string(),
        super::FormatRule::SameAs(of) => {
            format!("format of {}", graph.label(*of))
        }
    };
    format!("{size} {format} {}", p.colorspace)
}

/// Data edges labelled with the input they feed; feedback edges dashed, from
/// the pass whose earlier output they read.
fn write_edges(out: &mut String, graph: &Graph) {
    let g = &graph.graph;
    for e in g.edge_references() {
        let (s, t) = (e.source(), e.target());
        let label = match &g[t] {
            Node::Pass(p) => p
                .inputs
                .get(e.weight().input)
                .map(|i| i.name.clone())
                .unwrap_or_default(),
            _ => String::new(),
        };
        match &g[s] {
            Node::Feedback { pass, back } => {
                let _ = writeln!(
                    out,
                    "  n{} -> n{} [label=\"{} [-{back}]\", style=dashed, constraint=false];",
                    pass.index(),
                    t.index(),
                    esc(&label)
                );
            }
            _ => {
                let _ = writeln!(
                    out,
                    "  n{} -> n{} [label=\"{}\"];",
                    s.index(),
                    t.index(),
                    esc(&label)
                );
            }
        }
    }
}
