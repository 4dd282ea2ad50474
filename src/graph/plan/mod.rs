//! Resolution (sizes, formats, colour spaces for a given input) and the texture
//! lifetime plan: `Alloc / Run / Free` steps as plain data for the executor.
//!
//! Transient values (pass outputs read later in the same frame) get *slots*
//! (physical textures). A value is allocated just before its producer runs and
//! freed right after its last reader. A freed slot is reused by a later value of the
//! same descriptor; with [`ReusePolicy::MinPeak`] (the default) it is kept idle for
//! that only when holding it does not raise the peak above the live-set lower bound,
//! otherwise it is released and a new one created later. So on every graph the
//! plan's peak equals the lower bound (`peak_bytes == lower_bound_bytes`).

use super::{FormatRule, Graph, Node, SizeRule};
use crate::script::ast::MAX_SIDE;
use crate::script::jitter::JitterPattern;
use crate::script::types::{ColorSpace, Format, Sampling};
use crate::script::{Diagnostic, Diagnostics};
use petgraph::graph::NodeIndex;
use petgraph::Direction;
use serde::Serialize;
use std::collections::HashMap;

mod report;
mod resolve;
mod slots;

use resolve::Resolver;
use slots::{assign_slots, resource_of};

/// What the graph is run on.
#[derive(Debug, Clone, Serialize)]
pub struct InputDesc {
    pub width: u32,
    pub height: u32,
    /// Format of the input texture (`IN`).
    pub format: Format,
    /// What the input's sampled values mean.
    pub colorspace: ColorSpace,
    /// Auxiliary images available (same size as the input).
    pub aux: Vec<(String, Format)>,
}

impl InputDesc {
    /// An 8-bit sRGB image (e.g. a PNG photo), sampled as linear light.
    pub fn rgba8_srgb(width: u32, height: u32) -> Self {
        InputDesc {
            width,
            height,
            format: Format::Rgba8Srgb,
            colorspace: ColorSpace::Linear,
            aux: Vec::new(),
        }
    }

    /// Adds every other auxiliary input `graph` reads, as an 8-bit sRGB image
    /// (what `fxrun --aux NAME=photo.png` provides).
    pub fn with_aux_of(mut self, graph: &super::Graph) -> Self {
        for name in graph.aux_inputs() {
            if !self.aux.iter().any(|(a, _)| *a == name) {
                self.aux.push((name, Format::Rgba8Srgb));
            }
        }
        self
    }

    /// Sets the auxiliary inputs to `aux` (names and formats), e.g. the images
    /// the deferred renderer publishes (`deferred::published_aux`).
    pub fn with_aux(mut self, aux: &[(String, Format)]) -> Self {
        self.aux = aux.to_vec();
        self
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum ReusePolicy {
    /// Reuse a freed texture only where that keeps the peak at the lower bound.
    #[default]
    MinPeak,
    /// Keep every freed texture for reuse (fewer creations, possibly higher peak).
    Pool,
}

#[derive(Debug, Clone, Default)]
pub struct PlanOptions {
    pub policy: ReusePolicy,
    /// Format of the output target (e.g. the caller's texture, or rgba8-srgb for a
    /// PNG). `None`: the output pass's own format.
    pub output_format: Option<Format>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct TextureDesc {
    pub width: u32,
    pub height: u32,
    pub format: Format,
}

impl TextureDesc {
    pub fn bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * self.format.bytes_per_pixel()
    }
}

/// An image a pass reads or writes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Resource {
    /// The input frame `frame` frames from the current one.
    Input {
        frame: i32,
    },
    Aux(String),
    /// A transient value (index into `Plan::values`).
    Value(usize),
    /// The output of `ring`'s pass `back` frames ago (0: this frame).
    Persistent {
        ring: usize,
        back: u32,
    },
    /// The output target.
    Output,
}

/// How an input texture is viewed when sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum View {
    /// As stored.
    Natural,
    /// An 8-bit texture viewed as sRGB, so sampling decodes to linear.
    SrgbDecode,
    /// An sRGB texture viewed as plain 8-bit, so sampling returns encoded values.
    Raw,
}

#[derive(Debug, Clone, Serialize)]
pub struct PlannedInput {
    pub name: String,
    pub resource: Resource,
    pub view: View,
    pub sampling: Sampling,
    pub desc: TextureDesc,
}

/// What a pass runs: a shader from the script, or a built-in helper.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum PassShader {
    Script {
        name: String,
    },
    /// Colour-space conversion inserted by the compiler.
    Convert {
        to: ColorSpace,
    },
    /// Copies its input to the output target (format conversion included).
    Blit,
}

#[derive(Debug, Clone, Serialize)]
pub struct PlannedPass {
    /// Graph node of a script pass; `None` for inserted passes.
    #[serde(skip)]
    pub node: Option<NodeIndex>,
    pub path: String,
    pub shader: PassShader,
    pub inputs: Vec<PlannedInput>,
    pub output: Resource,
    pub desc: TextureDesc,
    pub colorspace: ColorSpace,
    /// How the output texture is viewed when rendering: `Raw` writes sRGB-encoded
    /// values into an `rgba8-srgb` target as they are (no second encoding).
    pub target_view: View,
}

/// A transient value: the output of one pass, alive from its producer to its last reader.
#[derive(Debug, Clone, Serialize)]
pub struct Value {
    pub desc: TextureDesc,
    pub producer: usize,
    pub last_reader: usize,
    pub slot: usize,
}

/// A persistent ring of the last `depth + 1` outputs of a pass (feedback).
#[derive(Debug, Clone, Serialize)]
pub struct Ring {
    pub pass: String,
    pub desc: TextureDesc,
    pub depth: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Step {
    /// Bind `value` to `slot`, creating the slot's texture if `create`.
    Alloc {
        value: usize,
        slot: usize,
        create: bool,
    },
    Run {
        pass: usize,
    },
    /// `value` is dead. If `release`, the slot's texture is destroyed; otherwise it
    /// is kept for a later value of the same descriptor.
    Free {
        value: usize,
        slot: usize,
        release: bool,
    },
}

#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    pub input: InputDesc,
    pub passes: Vec<PlannedPass>,
    pub values: Vec<Value>,
    /// Descriptor of each slot (physical transient texture).
    pub slots: Vec<TextureDesc>,
    pub rings: Vec<Ring>,
    pub steps: Vec<Step>,
    /// Bytes if every transient value had its own texture.
    pub naive_bytes: u64,
    /// Largest bytes of transient textures held at one moment by this plan.
    pub peak_bytes: u64,
    /// Largest sum of bytes of values live at one moment (no plan can do better
    /// for this schedule).
    pub lower_bound_bytes: u64,
    /// Bytes of feedback rings and input history kept across frames.
    pub persistent_bytes: u64,
    pub latency: u32,
    pub history: u32,
    /// The sub-pixel jitter the graph asks its input frames to be rendered with
    /// (`JITTER = halton23` in an effect), `None`: none (see [`Graph::jitter`]).
    pub jitter: Option<JitterPattern>,
    pub output: TextureDesc,
}

impl Plan {
    /// True when an effect of the plan asks for jittered input frames: the frame
    /// source should render frame `n` offset by `self.jitter.offset(n)` and give
    /// that offset with the frame (`FrameInputs::jitter`).
    pub fn wants_jitter(&self) -> bool {
        self.jitter.is_some()
    }
}
/// Resolve the graph for `input` and plan texture lifetimes. Errors (an aux input
/// not provided, an oversized pass, ...) are returned as diagnostics.
pub fn plan(
    graph: &Graph,
    input: &InputDesc,
    opts: &PlanOptions,
) -> Result<(Plan, Diagnostics), Diagnostics> {
    let mut r = Resolver {
        graph,
        input,
        sizes: HashMap::new(),
        diags: Diagnostics::default(),
    };
    let g = &graph.graph;
    // Auxiliary inputs must be provided.
    for n in g.node_indices() {
        if let Node::Aux { name, span } = &g[n] {
            let used = g
                .neighbors_directed(n, Direction::Outgoing)
                .any(|m| graph.schedule.contains(&m));
            if used && !input.aux.iter().any(|(a, _)| a == name) {
                let avail: Vec<&str> = input.aux.iter().map(|(a, _)| a.as_str()).collect();
                let mut d =
                    Diagnostic::error(format!("auxiliary input `AUX.{name}` is not provided"))
                        .at(*span, "not available");
                d = if avail.is_empty() {
                    d.note("auxiliary inputs come from the deferred renderer (`--scene`) or `--aux NAME=FILE`")
                } else {
                    d.note(format!("available: {}", avail.join(", ")))
                };
                r.diags.push(d);
            }
        }
    }
    // Feedback rings: one per pass whose earlier outputs are read.
    let mut ring_of: HashMap<NodeIndex, usize> = HashMap::new();
    let mut rings: Vec<Ring> = Vec::new();
    for n in g.node_indices() {
        if let Node::Feedback { pass, back } = g[n] {
            let reads = g
                .neighbors_directed(n, Direction::Outgoing)
                .any(|m| graph.schedule.contains(&m));
            if !reads {
                continue;
            }
            let Some(desc) = r.desc(pass) else { continue };
            let idx = *ring_of.entry(pass).or_insert_with(|| {
                rings.push(Ring {
                    pass: graph.pass(pass).path.clone(),
                    desc,
                    depth: 0,
                });
                rings.len() - 1
            });
            rings[idx].depth = rings[idx].depth.max(back);
        }
    }
    // Script passes in schedule order, each writing a transient value, a ring, or the output.
    let out_src = graph.output_source();
    let mut passes: Vec<PlannedPass> = Vec::new();
    let mut produced: HashMap<NodeIndex, Resource> = HashMap::new();
    let mut conversions: HashMap<(NodeIndex, ColorSpace), Resource> = HashMap::new();
    let mut values: Vec<Value> = Vec::new();
    let live_readers = |n: NodeIndex| -> usize {
        g.neighbors_directed(n, Direction::Outgoing)
            .filter(|m| graph.schedule.contains(m))
            .count()
    };
    // sRGB-encoded results go to a float output only through a conversion to linear.
    let srgb_to_float = r.colorspace(out_src) == ColorSpace::Srgb
        && opts
            .output_format
            .unwrap_or_else(|| r.format(out_src, 0))
            .is_float();
    let output_direct = matches!(g[out_src], Node::Pass(_))
        && live_readers(out_src) == 0
        && !ring_of.contains_key(&out_src)
        && !srgb_to_float;
    // Encoded values into an sRGB target are written through a raw 8-bit view.
    let output_view = |format: Format, cs: ColorSpace| {
        if format == Format::Rgba8Srgb && cs == ColorSpace::Srgb {
            View::Raw
        } else {
            View::Natural
        }
    };
    // `stored` is `srgb` or `linear` depending on the input.
    let space = |c: ColorSpace| c.resolve(input.format, input.colorspace);
    for &n in &graph.schedule {
        let p = graph.pass(n);
        let p_space = space(p.colorspace);
        let Some(mut desc) = r.desc(n) else { continue };
        if p_space == ColorSpace::Srgb && desc.format.is_srgb() {
            r.diags.push(
                Diagnostic::error(format!("pass `{}` writes sRGB-encoded values into an rgba8-srgb texture, which encodes them again", p.path))
                    .at(p.name_span, "double sRGB encoding")
                    .note("use OUT.FORMAT = rgba8 with OUT.COLORSPACE = srgb, or keep COLORSPACE linear"),
            );
        }
        let mut inputs = Vec::new();
        for (inp, src) in graph.inputs_with_sources(n) {
            let Some(src_desc) = r.desc(src) else {
                continue;
            };
            let have = r.colorspace(src);
            let want = space(inp.colorspace);
            let mut resource = resource_of(graph, src, &produced, &ring_of);
            let mut view = View::Natural;
            let mut in_desc = src_desc;
            if have != want {
                match (src_desc.format, have, want) {
                    (Format::Rgba8Srgb, ColorSpace::Linear, ColorSpace::Srgb) => view = View::Raw,
                    (Format::Rgba8, ColorSpace::Srgb, ColorSpace::Linear) => {
                        view = View::SrgbDecode
                    }
                    _ => {
                        // An explicit conversion pass (once per source and target space).
                        let key = (src, want);
                        if let Some(res) = conversions.get(&key) {
                            resource = res.clone();
                        } else {
                            let conv_format = if src_desc.format.is_float() {
                                src_desc.format
                            } else {
                                Format::Rgba16f
                            };
                            let conv_desc = TextureDesc {
                                format: conv_format,
                                ..src_desc
                            };
                            r.diags.push(
                                Diagnostic::note_diag(format!(
                                    "`{}` is {have} but pass `{}` expects its input `{}` in {}: converting with an extra pass",
                                    graph.label(src),
                                    p.path,
                                    inp.name,
                                    want
                                ))
                                .at(inp.span, format!("converted from {have} to {}", want)),
                            );
                            let v = values.len();
                            values.push(Value {
                                desc: conv_desc,
                                producer: passes.len(),
                                last_reader: passes.len(),
                                slot: 0,
                            });
                            passes.push(PlannedPass {
                                node: None,
                                path: format!("{}:{}:{}", p.path, inp.name, want),
                                shader: PassShader::Convert { to: want },
                                inputs: vec![PlannedInput {
                                    name: "img".into(),
                                    resource: resource.clone(),
                                    view: View::Natural,
                                    sampling: Sampling::default(),
                                    desc: src_desc,
                                }],
                                output: Resource::Value(v),
                                desc: conv_desc,
                                colorspace: want,
                                target_view: View::Natural,
                            });
                            resource = Resource::Value(v);
                            conversions.insert(key, resource.clone());
                        }
                        in_desc = match &resource {
                            Resource::Value(v) => values[*v].desc,
                            _ => src_desc,
                        };
                    }
                }
            }
            inputs.push(PlannedInput {
                name: inp.name.clone(),
                resource,
                view,
                sampling: inp.sampling,
                desc: in_desc,
            });
        }
        let mut target_view = View::Natural;
        let output = if n == out_src && output_direct {
            if let Some(f) = opts.output_format {
                desc.format = f;
            }
            target_view = output_view(desc.format, p_space);
            Resource::Output
        } else if let Some(&ring) = ring_of.get(&n) {
            Resource::Persistent { ring, back: 0 }
        } else {
            values.push(Value {
                desc,
                producer: passes.len(),
                last_reader: passes.len(),
                slot: 0,
            });
            Resource::Value(values.len() - 1)
        };
        produced.insert(n, output.clone());
        passes.push(PlannedPass {
            node: Some(n),
            path: p.path.clone(),
            shader: PassShader::Script {
                name: p.shader.clone(),
            },
            inputs,
            output,
            desc,
            colorspace: p_space,
            target_view,
        });
    }
    // The output target, when the output pass could not write it directly.
    let output_desc;
    if output_direct {
        output_desc = passes
            .iter()
            .find(|p| p.output == Resource::Output)
            .map(|p| p.desc)
            .unwrap_or(TextureDesc {
                width: input.width,
                height: input.height,
                format: input.format,
            });
    } else {
        let Some(src_desc) = r.desc(out_src) else {
            return Err(r.diags);
        };
        let resource = resource_of(graph, out_src, &produced, &ring_of);
        output_desc = TextureDesc {
            format: opts.output_format.unwrap_or(src_desc.format),
            ..src_desc
        };
        let src_cs = r.colorspace(out_src);
        let (shader, colorspace) = if srgb_to_float {
            (
                PassShader::Convert {
                    to: ColorSpace::Linear,
                },
                ColorSpace::Linear,
            )
        } else {
            (PassShader::Blit, src_cs)
        };
        passes.push(PlannedPass {
            node: None,
            path: "OUT".into(),
            shader,
            inputs: vec![PlannedInput {
                name: "img".into(),
                resource,
                view: View::Natural,
                sampling: Sampling::default(),
                desc: src_desc,
            }],
            output: Resource::Output,
            desc: output_desc,
            colorspace,
            target_view: output_view(output_desc.format, colorspace),
        });
    }
    if r.diags.has_errors() {
        r.diags.sort();
        return Err(r.diags);
    }
    // Last readers.
    for (i, p) in passes.iter().enumerate() {
        for inp in &p.inputs {
            if let Resource::Value(v) = inp.resource {
                values[v].last_reader = values[v].last_reader.max(i);
            }
        }
    }
    let (slots, steps, peak, lower) = assign_slots(&mut values, passes.len(), opts.policy);
    let naive = values.iter().map(|v| v.desc.bytes()).sum();
    let in_bytes = TextureDesc {
        width: input.width,
        height: input.height,
        format: input.format,
    }
    .bytes();
    let persistent = rings
        .iter()
        .map(|r| r.desc.bytes() * (r.depth as u64 + 1))
        .sum::<u64>()
        + in_bytes * (graph.history + graph.latency) as u64;
    let mut diags = r.diags;
    diags.sort();
    Ok((
        Plan {
            input: input.clone(),
            passes,
            values,
            slots,
            rings,
            steps,
            naive_bytes: naive,
            peak_bytes: peak,
            lower_bound_bytes: lower,
            persistent_bytes: persistent,
            latency: graph.latency,
            history: graph.history,
            jitter: graph.jitter,
            output: output_desc,
        },
        diags,
    ))
}
