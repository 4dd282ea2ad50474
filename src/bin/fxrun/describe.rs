//! `fxrun`: `--describe`: an effect's passes, parameters and settable pass fields.

use super::*;

/// The settable pass parameters of `graph` with the `--set` key of each:
/// `PASS.NAME`, or `EFFECT/PASS.NAME` where passes of two effects share a name.
pub(crate) fn pass_param_rows(
    graph: &fxgraph::graph::Graph,
) -> Vec<(String, fxgraph::shader::PassParamInfo)> {
    let infos = fxgraph::shader::pass_parameters(graph, &[]);
    let shared = |short: &str| {
        graph
            .schedule
            .iter()
            .filter(|&&n| graph.pass(n).path.rsplit('/').next() == Some(short))
            .count()
            > 1
    };
    // `--set EFFECT.NAME` goes to an effect parameter of that name first.
    let effect_keys: Vec<String> = graph
        .params
        .iter()
        .map(|p| format!("{}.{}", p.effect, p.name))
        .collect();
    infos
        .into_iter()
        .map(|p| {
            let short = format!("{}.{}", p.pass_name, p.name);
            let key = if shared(&p.pass_name) || effect_keys.contains(&short) {
                format!("{}.{}", p.pass, p.name)
            } else {
                short
            };
            (key, p)
        })
        .collect()
}

pub(crate) fn describe(graph: &fxgraph::graph::Graph) {
    for (name, desc) in &graph.descriptions {
        outln!("effect {name}");
        for line in desc.lines() {
            outln!("  {line}");
        }
    }
    describe_passes(graph);
    describe_params(graph);
    describe_pass_params(graph);
    if graph.has_feedback() {
        outln!("temporal: uses feedback (earlier output frames); a sharded sequence run needs warm-up frames");
    }
    if graph.latency > 0 || graph.history > 0 {
        outln!(
            "temporal: reads {} earlier and {} later input frames (latency {})",
            graph.history,
            graph.latency,
            graph.latency
        );
    }
    if let Some(j) = graph.jitter {
        outln!(
            "jitter: {j} (asks for input frames rendered with sub-pixel offsets, period {}; the renderer applies them)",
            j.period()
        );
    }
}

/// The passes in execution order, with their shaders and inputs.
fn describe_passes(graph: &fxgraph::graph::Graph) {
    outln!("passes (in execution order):");
    for &n in &graph.schedule {
        let p = graph.pass(n);
        let inputs: Vec<String> = graph
            .inputs_with_sources(n)
            .map(|(inp, src)| format!("{}={}", inp.name, graph.label(src)))
            .collect();
        outln!(
            "  {:<28} SHADER.{:<16} {}",
            p.path,
            p.shader,
            inputs.join(" ")
        );
    }
}

/// The effect parameters: type, value, default, range or choices, description.
fn describe_params(graph: &fxgraph::graph::Graph) {
    if graph.params.is_empty() {
        outln!("parameters: none");
    } else {
        outln!("parameters:");
        for p in &graph.params {
            let step = p
                .step
                .map(|s| format!(" step {}", format_value(&[s])))
                .unwrap_or_default();
            let range = p
                .range
                .map(|(a, b)| {
                    format!(
                        " range [{}, {}]{step}",
                        format_value(&[a]),
                        format_value(&[b])
                    )
                })
                .unwrap_or(step);
            let choices = match &p.ty {
                fxgraph::script::types::ParamType::Enum(v) => format!(" one of {}", v.join("|")),
                _ => String::new(),
            };
            // ENUM values by name, BOOL as true/false.
            let show = |v: &[f64]| match &p.ty {
                fxgraph::script::types::ParamType::Enum(names) => names
                    .get(v[0] as usize)
                    .cloned()
                    .unwrap_or_else(|| format_value(v)),
                fxgraph::script::types::ParamType::Bool => (v[0] != 0.0).to_string(),
                _ => format_value(v),
            };
            outln!(
                "  {}.{:<14} {:<5} = {:<10} (default {}){range}{choices}  {}",
                p.effect,
                p.name,
                p.ty.name(),
                show(&p.value),
                show(&p.default),
                p.description
            );
        }
    }
}

/// The pass parameters `--set PASS.NAME=VALUE` takes, and those the effect sets.
fn describe_pass_params(graph: &fxgraph::graph::Graph) {
    let rows = pass_param_rows(graph);
    if rows.is_empty() {
        outln!("pass parameters: none");
    } else {
        outln!("pass parameters (--set PASS.NAME=VALUE):");
        let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0).max(20);
        for (key, p) in rows {
            let default = p
                .default
                .as_ref()
                .map_or_else(|| "none".to_string(), |d| format_value(d));
            let value = p
                .set
                .as_ref()
                .or(p.default.as_ref())
                .map_or_else(|| "-".to_string(), |v| format_value(v));
            let range = p
                .range
                .map(|(a, b)| format!(" range [{}, {}]", format_value(&[a]), format_value(&[b])))
                .unwrap_or_default();
            let by_effect = if p.set.is_some() {
                " (set by the effect)"
            } else {
                ""
            };
            outln!(
                "  {key:<width$} {:<9} = {value:<10} (default {default}){range}{by_effect}  {}",
                p.ty.wgsl(),
                p.description
            );
        }
    }
}
