//! RetroArch slang presets (`.slangp`) as effects. The librashader crates parse
//! the preset (`#reference` chains, wildcards), preprocess each `.slang` file
//! (includes, `#pragma parameter`, `#pragma format`) and translate its GLSL to
//! naga's IR; this module lowers the result onto the graph: an EFFECT script
//! (passes, inputs, sizes, formats, samplers, history and feedback, parameters)
//! and one WGSL fragment shader per pass in fxgraph's conventions, so planning,
//! execution, `--describe`, `--set` and timings are those of any effect
//! (docs/slang.md).

mod builtins;
mod compile;
mod error;
mod line_markers;
mod lower;
mod rewrite;
mod script;
mod varyings;
mod vertex;
mod words;

pub use error::{FailureClass, SlangError};
pub use lower::{is_preset, lower_preset, parse_preset, preset_files, Lowered};
