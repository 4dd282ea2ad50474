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

use super::{AxisSize, FormatRule, Graph, Node, PassNode, SizeRule};
use crate::script::ast::MAX_SIDE;
use crate::script::jitter::JitterPattern;
use crate::script::types::{ColorSpace, Format, Sampling};
use crate::script::{Diagnostic, Diagnostics};
use petgraph::graph::NodeIndex;
use serde::Serialize;
use std::collections::HashMap;

mod planner;
mod report;
mod resolve;
mod slots;

use planner::Planner;

/// What the graph is run on.
#[derive(Debug, Clone, Serialize)]
pub struct InputDesc {
    pub width: u32,
    pub height: u32,
    /// Format of the input texture (`IN`).
    pub format: Format,
    /// What the input's sampled values mean.
    pub colorspace: ColorSpace,
    /// Auxiliary images available (of the input's size unless `aux_sizes`
    /// gives theirs).
    pub aux: Vec<(String, Format)>,
    /// Auxiliary images of their own size (an image given with `--aux`, a
    /// slang preset's LUT): `(name, (width, height))`. An auxiliary image not
    /// listed has the input's size (the renderer's G-buffer).
    pub aux_sizes: Vec<(String, (u32, u32))>,
    /// The run's output size, which passes scale from as `VIEWPORT`
    /// (`None`: the input's size).
    pub viewport: Option<(u32, u32)>,
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
            aux_sizes: Vec::new(),
            viewport: None,
        }
    }

    /// The run's output size: [`InputDesc::viewport`], or the input's size.
    pub fn viewport(&self) -> (u32, u32) {
        self.viewport.unwrap_or((self.width, self.height))
    }

    /// Sets the run's output size (`VIEWPORT` in size rules).
    pub fn with_viewport(mut self, viewport: Option<(u32, u32)>) -> Self {
        self.viewport = viewport;
        self
    }

    /// Gives auxiliary image `name` its own size `(width, height)`.
    pub fn with_aux_size(mut self, name: &str, size: (u32, u32)) -> Self {
        self.aux_sizes.retain(|(n, _)| n != name);
        self.aux_sizes.push((name.to_string(), size));
        self
    }

    /// The size of auxiliary image `name`: its own, or the input's.
    pub fn aux_size(&self, name: &str) -> (u32, u32) {
        self.aux_sizes
            .iter()
            .find(|(n, _)| n == name)
            .map_or((self.width, self.height), |(_, s)| *s)
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
    /// Mip levels: 1, or the full chain down to 1x1 for an input read with
    /// `NAME.MIPMAP = true` ([`mip_levels`]). Left out of JSON when 1.
    #[serde(skip_serializing_if = "one_level")]
    pub mips: u32,
}

impl TextureDesc {
    /// A texture of one mip level.
    pub fn new(width: u32, height: u32, format: Format) -> Self {
        TextureDesc {
            width,
            height,
            format,
            mips: 1,
        }
    }

    /// Bytes of all its mip levels.
    pub fn bytes(&self) -> u64 {
        (0..self.mips)
            .map(|l| {
                let (w, h) = mip_size((self.width, self.height), l);
                w as u64 * h as u64 * self.format.bytes_per_pixel()
            })
            .sum()
    }
}

fn one_level(mips: &u32) -> bool {
    *mips == 1
}

/// The levels of a full mip chain of a `width` x `height` texture, down to 1x1:
/// `floor(log2(max(width, height))) + 1` (what RetroArch and librashader make).
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// The size of mip level `level` of a `(width, height)` texture: each side
/// halved (rounded down) per level, at least 1.
pub fn mip_size((width, height): (u32, u32), level: u32) -> (u32, u32) {
    ((width >> level).max(1), (height >> level).max(1))
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
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
    /// Copies its input into level 0 of a mipmapped value (an input read with
    /// `NAME.MIPMAP = true` that is not a pass output of this frame: `IN`,
    /// `AUX.x`, history, feedback). The executor then makes the other levels.
    Mips,
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
    let mut planner = Planner::new(graph, input, opts);
    planner.check_aux_inputs();
    planner.collect_rings();
    let route = planner.output_route();
    for &n in &graph.schedule {
        planner.plan_script_pass(n, &route);
    }
    let Some(output) = planner.plan_output_target(&route) else {
        return Err(planner.into_diagnostics());
    };
    if let Some(errors) = planner.errors() {
        return Err(errors);
    }
    Ok(planner.finish(output))
}
