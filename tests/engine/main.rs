//! The language's, the graph's, the shaders', the executor's and the tools'
//! tests, one binary: each `tests/NAME.rs` listed here is a module of it
//! (`cargo test --test engine NAME::`). One binary instead of one per file:
//! linking each cost CI minutes. The files stay where they are.

#[path = "../common/mod.rs"]
mod common;

#[path = "../bench_gpu.rs"]
mod bench_gpu;
#[path = "../compute_native.rs"]
mod compute_native;
#[path = "../diagnostics.rs"]
mod diagnostics;
#[path = "../effect_lookup.rs"]
mod effect_lookup;
#[path = "../execution.rs"]
mod execution;
#[path = "../gpu_context.rs"]
mod gpu_context;
#[path = "../graph.rs"]
mod graph;
#[path = "../hostile_input.rs"]
mod hostile_input;
#[path = "../inspect.rs"]
mod inspect;
#[path = "../language_docs.rs"]
mod language_docs;
#[path = "../layers.rs"]
mod layers;
#[path = "../library.rs"]
mod library;
#[path = "../mipmap.rs"]
mod mipmap;
#[path = "../relative_paths.rs"]
mod relative_paths;
#[path = "../shaders.rs"]
mod shaders;
#[path = "../slang.rs"]
mod slang;
#[path = "../temporal.rs"]
mod temporal;
#[path = "../tonemap.rs"]
mod tonemap;
#[path = "../watch.rs"]
mod watch;
#[path = "../yuv_gpu.rs"]
mod yuv_gpu;
