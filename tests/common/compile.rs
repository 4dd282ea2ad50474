//! Compiling effects as the CLI compiles them, for the tests of the compiler and
//! of what it is given.
#![allow(dead_code)]

use fxgraph::graph::{compile, CompileRequest, Graph, Override};
use fxgraph::script::{Diagnostics, SourceMap};
use std::path::Path;

/// The chain `effects` (names or paths) compiled as the CLI compiles it (effects
/// looked up on disk), with the `--set` arguments `sets`.
pub fn compile_chain(effects: &[String], sets: &[&str]) -> (Option<Graph>, Diagnostics, SourceMap) {
    compile(&CompileRequest {
        source: Some(std::sync::Arc::new(fxgraph::lookup::DiskEffects::default())),
        effects: effects.to_vec(),
        overrides: sets.iter().map(|a| Override::parse(a)).collect(),
    })
}

/// The effect file at `path` compiled as the CLI compiles it.
pub fn compile_file(path: &Path) -> (Option<Graph>, Diagnostics, SourceMap) {
    compile_chain(&[path.display().to_string()], &[])
}
