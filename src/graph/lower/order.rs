//! Ordering the graph: dependency cycles reported whole, then the schedule.

use super::*;

/// Report every dependency cycle (feedback edges excluded). True if any.
pub(super) fn report_cycles(graph: &Graph, diags: &mut Diagnostics) -> bool {
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
pub(super) fn schedule(graph: &mut Graph, diags: &mut Diagnostics) {
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
