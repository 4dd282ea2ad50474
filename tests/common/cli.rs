//! Running the real `fxrun` binary from a test.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// `fxrun ARGS` in the repository's root.
pub fn fxrun(args: &[&str]) -> Output {
    fxrun_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// `fxrun ARGS` in `dir`.
pub fn fxrun_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fxrun"))
        .args(args)
        .current_dir(dir)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("run fxrun")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The exit status (-1 when killed by a signal).
pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}
