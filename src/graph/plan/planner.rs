//! The steps of [`super::plan`]: checking the auxiliary inputs, gathering the
//! feedback rings, planning each script pass (with the colour-space conversions
//! its inputs need) and the output target, then measuring the plan.

use super::resolve::Resolver;
use super::slots::{assign_slots, resource_of};
use super::{
    InputDesc, PassShader, Plan, PlanOptions, PlannedInput, PlannedPass, Resource, Ring,
    TextureDesc, Value, View,
};
use crate::graph::{Graph, Node, PassInput, PassNode};
use crate::script::types::{ColorSpace, Format, Sampling};
use crate::script::{Diagnostic, Diagnostics};
use petgraph::graph::NodeIndex;
use petgraph::Direction;
use std::collections::HashMap;

/// Where the graph's output source goes: straight into the output target, or
/// through a final blit or conversion pass.
pub(super) struct OutputRoute {
    /// The node the output reads.
    source: NodeIndex,
    /// The source is sRGB-encoded but the target is a float format: it needs a
    /// conversion to linear.
    srgb_to_float: bool,
    /// The output pass writes the target itself.
    direct: bool,
}

/// The state a plan is built in, pass by pass.
pub(super) struct Planner<'g> {
    graph: &'g Graph,
    input: &'g InputDesc,
    opts: &'g PlanOptions,
    r: Resolver<'g>,
    ring_of: HashMap<NodeIndex, usize>,
    rings: Vec<Ring>,
    passes: Vec<PlannedPass>,
    produced: HashMap<NodeIndex, Resource>,
    conversions: HashMap<(NodeIndex, ColorSpace), Resource>,
    /// Mipmapped copies of inputs that are not this frame's pass outputs.
    mip_copies: HashMap<(NodeIndex, View), Resource>,
    values: Vec<Value>,
}

/// Encoded values into an sRGB target are written through a raw 8-bit view.
fn output_view(format: Format, cs: ColorSpace) -> View {
    if format == Format::Rgba8Srgb && cs == ColorSpace::Srgb {
        View::Raw
    } else {
        View::Natural
    }
}

impl<'g> Planner<'g> {
    pub(super) fn new(graph: &'g Graph, input: &'g InputDesc, opts: &'g PlanOptions) -> Self {
        Planner {
            graph,
            input,
            opts,
            r: Resolver {
                graph,
                input,
                sizes: HashMap::new(),
                diags: Diagnostics::default(),
            },
            ring_of: HashMap::new(),
            rings: Vec::new(),
            passes: Vec::new(),
            produced: HashMap::new(),
            conversions: HashMap::new(),
            mip_copies: HashMap::new(),
            values: Vec::new(),
        }
    }

    /// True when a scheduled pass reads node `n`.
    fn is_read(&self, n: NodeIndex) -> bool {
        self.graph
            .graph
            .neighbors_directed(n, Direction::Outgoing)
            .any(|m| self.graph.schedule.contains(&m))
    }

    /// How many scheduled passes read node `n`.
    fn live_readers(&self, n: NodeIndex) -> usize {
        self.graph
            .graph
            .neighbors_directed(n, Direction::Outgoing)
            .filter(|m| self.graph.schedule.contains(m))
            .count()
    }

    /// `stored` is `srgb` or `linear` depending on the input.
    fn space(&self, c: ColorSpace) -> ColorSpace {
        c.resolve(self.input.format, self.input.colorspace)
    }

    /// Auxiliary inputs must be provided.
    pub(super) fn check_aux_inputs(&mut self) {
        let g = &self.graph.graph;
        for n in g.node_indices() {
            if let Node::Aux { name, span } = &g[n] {
                if self.is_read(n) && !self.input.aux.iter().any(|(a, _)| a == name) {
                    let avail: Vec<&str> = self.input.aux.iter().map(|(a, _)| a.as_str()).collect();
                    let mut d =
                        Diagnostic::error(format!("auxiliary input `AUX.{name}` is not provided"))
                            .at(*span, "not available");
                    d = if avail.is_empty() {
                        d.note("auxiliary inputs come from the deferred renderer (`--scene`) or `--aux NAME=FILE`")
                    } else {
                        d.note(format!("available: {}", avail.join(", ")))
                    };
                    self.r.diags.push(d);
                }
            }
        }
    }

    /// Feedback rings: one per pass whose earlier outputs are read.
    pub(super) fn collect_rings(&mut self) {
        let g = &self.graph.graph;
        for n in g.node_indices() {
            if let Node::Feedback { pass, back } = g[n] {
                if !self.is_read(n) {
                    continue;
                }
                let Some(desc) = self.r.desc(pass) else {
                    continue;
                };
                let rings = &mut self.rings;
                let idx = *self.ring_of.entry(pass).or_insert_with(|| {
                    rings.push(Ring {
                        pass: self.graph.pass(pass).path.clone(),
                        desc,
                        depth: 0,
                    });
                    rings.len() - 1
                });
                rings[idx].depth = rings[idx].depth.max(back);
            }
        }
    }

    /// Whether the output pass can write the output target itself.
    pub(super) fn output_route(&self) -> OutputRoute {
        let source = self.graph.output_source();
        // sRGB-encoded results go to a float output only through a conversion to linear.
        let srgb_to_float = self.r.colorspace(source) == ColorSpace::Srgb
            && self
                .opts
                .output_format
                .unwrap_or_else(|| self.r.format(source, 0))
                .is_float();
        let direct = matches!(self.graph.graph[source], Node::Pass(_))
            && self.live_readers(source) == 0
            && !self.ring_of.contains_key(&source)
            && !srgb_to_float;
        OutputRoute {
            source,
            srgb_to_float,
            direct,
        }
    }

    /// A new transient value produced (and so far last read) by the next pass.
    fn push_value(&mut self, desc: TextureDesc) -> usize {
        self.values.push(Value {
            desc,
            producer: self.passes.len(),
            last_reader: self.passes.len(),
            slot: 0,
        });
        self.values.len() - 1
    }

    /// Script pass `n`, writing a transient value, a ring, or the output.
    pub(super) fn plan_script_pass(&mut self, n: NodeIndex, route: &OutputRoute) {
        let graph = self.graph;
        let p = graph.pass(n);
        let p_space = self.space(p.colorspace);
        let Some(mut desc) = self.r.desc(n) else {
            return;
        };
        if p_space == ColorSpace::Srgb && desc.format.is_srgb() {
            self.r.diags.push(
                Diagnostic::error(format!("pass `{}` writes sRGB-encoded values into an rgba8-srgb texture, which encodes them again", p.path))
                    .at(p.name_span, "double sRGB encoding")
                    .note("use OUT.FORMAT = rgba8 with OUT.COLORSPACE = srgb, or keep COLORSPACE linear"),
            );
        }
        let inputs: Vec<PlannedInput> = graph
            .inputs_with_sources(n)
            .filter_map(|(inp, src)| self.plan_input(p, inp, src))
            .collect();
        let mut target_view = View::Natural;
        let output = if n == route.source && route.direct {
            if let Some(f) = self.opts.output_format {
                desc.format = f;
            }
            target_view = output_view(desc.format, p_space);
            Resource::Output
        } else if let Some(&ring) = self.ring_of.get(&n) {
            Resource::Persistent { ring, back: 0 }
        } else {
            Resource::Value(self.push_value(desc))
        };
        self.produced.insert(n, output.clone());
        self.passes.push(PlannedPass {
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

    /// Input `inp` of pass `p`, read from `src` through a view or a conversion
    /// pass when the colour spaces differ. `None` when `src` has no size.
    fn plan_input(
        &mut self,
        p: &PassNode,
        inp: &PassInput,
        src: NodeIndex,
    ) -> Option<PlannedInput> {
        let src_desc = self.r.desc(src)?;
        let have = self.r.colorspace(src);
        let want = self.space(inp.colorspace);
        let mut resource = resource_of(self.graph, src, &self.produced, &self.ring_of);
        let mut view = View::Natural;
        let mut in_desc = src_desc;
        if have != want {
            match (src_desc.format, have, want) {
                (Format::Rgba8Srgb, ColorSpace::Linear, ColorSpace::Srgb) => view = View::Raw,
                (Format::Rgba8, ColorSpace::Srgb, ColorSpace::Linear) => view = View::SrgbDecode,
                _ => {
                    let conversion = Conversion {
                        pass: p,
                        input: inp,
                        src,
                        src_desc,
                        have,
                        want,
                    };
                    resource = self.converted(&conversion, resource);
                    in_desc = match &resource {
                        Resource::Value(v) => self.values[*v].desc,
                        _ => src_desc,
                    };
                }
            }
        }
        if inp.sampling.mipmap {
            (resource, view, in_desc) = self.mipmapped(p, inp, src, (resource, view, in_desc));
        }
        Some(PlannedInput {
            name: inp.name.clone(),
            resource,
            view,
            sampling: inp.sampling,
            desc: in_desc,
        })
    }

    /// Input `inp` (`NAME.MIPMAP = true`) read with a full mip chain: a value of
    /// this frame gets the chain itself (the executor makes its levels after its
    /// producer writes it); any other resource is first copied into a new value
    /// that has one (a `Mips` pass, once per source and view). Returns what the
    /// pass then reads: the resource, its view, its descriptor.
    fn mipmapped(
        &mut self,
        p: &PassNode,
        inp: &PassInput,
        src: NodeIndex,
        (resource, view, desc): (Resource, View, TextureDesc),
    ) -> (Resource, View, TextureDesc) {
        let mips = super::mip_levels(desc.width, desc.height);
        if let Resource::Value(v) = resource {
            self.values[v].desc.mips = mips;
            return (resource, view, self.values[v].desc);
        }
        // The copy stores what the view reads, so the consumer reads it as is.
        let format = match view {
            View::Natural => desc.format,
            View::Raw => Format::Rgba8,
            View::SrgbDecode => Format::Rgba8Srgb,
        };
        let copy_desc = TextureDesc {
            format,
            mips,
            ..desc
        };
        if let Some(res) = self.mip_copies.get(&(src, view)) {
            return (res.clone(), View::Natural, copy_desc);
        }
        let v = self.push_value(copy_desc);
        let mut pass = engine_pass(
            format!("{}:{}:mips", p.path, inp.name),
            PassShader::Mips,
            resource,
            desc,
        );
        pass.inputs[0].view = view;
        self.passes.push(PlannedPass {
            output: Resource::Value(v),
            desc: TextureDesc {
                mips: 1,
                ..copy_desc
            },
            colorspace: self.space(inp.colorspace),
            target_view: View::Natural,
            ..pass
        });
        let res = Resource::Value(v);
        self.mip_copies.insert((src, view), res.clone());
        (res, View::Natural, copy_desc)
    }

    /// An explicit conversion pass (once per source and target space): the
    /// resource holding `c.src` converted, reading it from `resource`.
    fn converted(&mut self, c: &Conversion, resource: Resource) -> Resource {
        let key = (c.src, c.want);
        if let Some(res) = self.conversions.get(&key) {
            return res.clone();
        }
        let (src_desc, have, want) = (c.src_desc, c.have, c.want);
        let conv_format = if src_desc.format.is_float() {
            src_desc.format
        } else {
            Format::Rgba16f
        };
        let conv_desc = TextureDesc {
            format: conv_format,
            ..src_desc
        };
        self.r.diags.push(
            Diagnostic::note_diag(format!(
                "`{}` is {have} but pass `{}` expects its input `{}` in {}: converting with an extra pass",
                self.graph.label(c.src),
                c.pass.path,
                c.input.name,
                want
            ))
            .at(c.input.span, format!("converted from {have} to {}", want)),
        );
        let v = self.push_value(conv_desc);
        self.passes.push(PlannedPass {
            output: Resource::Value(v),
            desc: conv_desc,
            colorspace: want,
            target_view: View::Natural,
            ..engine_pass(
                format!("{}:{}:{}", c.pass.path, c.input.name, want),
                PassShader::Convert { to: want },
                resource,
                src_desc,
            )
        });
        let resource = Resource::Value(v);
        self.conversions.insert(key, resource.clone());
        resource
    }

    /// The output target's descriptor, adding a blit or conversion pass when the
    /// output pass could not write it directly. `None` when the output source
    /// has no size.
    pub(super) fn plan_output_target(&mut self, route: &OutputRoute) -> Option<TextureDesc> {
        if route.direct {
            return Some(
                self.passes
                    .iter()
                    .find(|p| p.output == Resource::Output)
                    .map(|p| p.desc)
                    .unwrap_or(TextureDesc::new(
                        self.input.width,
                        self.input.height,
                        self.input.format,
                    )),
            );
        }
        let src_desc = self.r.desc(route.source)?;
        let resource = resource_of(self.graph, route.source, &self.produced, &self.ring_of);
        let output_desc = TextureDesc {
            format: self.opts.output_format.unwrap_or(src_desc.format),
            ..src_desc
        };
        let src_cs = self.r.colorspace(route.source);
        let (shader, colorspace) = if route.srgb_to_float {
            (
                PassShader::Convert {
                    to: ColorSpace::Linear,
                },
                ColorSpace::Linear,
            )
        } else {
            (PassShader::Blit, src_cs)
        };
        self.passes.push(PlannedPass {
            output: Resource::Output,
            desc: output_desc,
            colorspace,
            target_view: output_view(output_desc.format, colorspace),
            ..engine_pass("OUT".into(), shader, resource, src_desc)
        });
        Some(output_desc)
    }

    /// The diagnostics so far, sorted, when one of them is an error.
    pub(super) fn errors(&mut self) -> Option<Diagnostics> {
        if self.r.diags.has_errors() {
            self.r.diags.sort();
            return Some(std::mem::take(&mut self.r.diags));
        }
        None
    }

    /// The diagnostics so far, as they are (the output source has no size).
    pub(super) fn into_diagnostics(self) -> Diagnostics {
        self.r.diags
    }

    /// Each value's last reader: the latest pass that reads it.
    fn mark_last_readers(&mut self) {
        for (i, p) in self.passes.iter().enumerate() {
            for inp in &p.inputs {
                if let Resource::Value(v) = inp.resource {
                    self.values[v].last_reader = self.values[v].last_reader.max(i);
                }
            }
        }
    }

    /// Bytes of feedback rings and input history kept across frames.
    fn persistent_bytes(&self) -> u64 {
        let in_bytes =
            TextureDesc::new(self.input.width, self.input.height, self.input.format).bytes();
        self.rings
            .iter()
            .map(|r| r.desc.bytes() * (r.depth as u64 + 1))
            .sum::<u64>()
            + in_bytes * (self.graph.history + self.graph.latency) as u64
    }

    /// Assigns slots and steps to the passes and measures the plan.
    pub(super) fn finish(mut self, output: TextureDesc) -> (Plan, Diagnostics) {
        self.mark_last_readers();
        let (slots, steps, peak, lower) =
            assign_slots(&mut self.values, self.passes.len(), self.opts.policy);
        let naive = self.values.iter().map(|v| v.desc.bytes()).sum();
        let persistent = self.persistent_bytes();
        let graph = self.graph;
        let mut diags = self.r.diags;
        diags.sort();
        (
            Plan {
                input: self.input.clone(),
                passes: self.passes,
                values: self.values,
                slots,
                rings: self.rings,
                steps,
                naive_bytes: naive,
                peak_bytes: peak,
                lower_bound_bytes: lower,
                persistent_bytes: persistent,
                latency: graph.latency,
                history: graph.history,
                jitter: graph.jitter,
                output,
            },
            diags,
        )
    }
}

/// An input read in another colour space than its source's: what the
/// conversion pass needs.
struct Conversion<'a> {
    pass: &'a PassNode,
    input: &'a PassInput,
    src: NodeIndex,
    src_desc: TextureDesc,
    have: ColorSpace,
    want: ColorSpace,
}

/// An engine pass (a conversion or the output's blit) of one input `img` read as
/// it is; the caller sets its output.
fn engine_pass(
    path: String,
    shader: PassShader,
    resource: Resource,
    desc: TextureDesc,
) -> PlannedPass {
    PlannedPass {
        node: None,
        path,
        shader,
        inputs: vec![PlannedInput {
            name: "img".into(),
            resource,
            view: View::Natural,
            sampling: Sampling::default(),
            desc,
        }],
        output: Resource::Output,
        desc,
        colorspace: ColorSpace::Linear,
        target_view: View::Natural,
    }
}
