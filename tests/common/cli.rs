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

/// `fxrun ARGS` in `dir`, with extra environment variables (`PATH` to hide ffmpeg)
/// and `stdin` as its standard input.
pub fn fxrun_with(dir: &Path, args: &[&str], env: &[(&str, &str)], stdin: &[u8]) -> Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_fxrun"))
        .args(args)
        .current_dir(dir)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .envs(env.iter().copied())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run fxrun");
    let mut input = child.stdin.take().expect("stdin");
    let data = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().expect("wait for fxrun");
    writer.join().expect("stdin writer");
    out
}

/// Assert that a run ended with `status` and that its stderr says each of `says`.
pub fn assert_run(o: &Output, status: i32, says: &[&str]) {
    let err = stderr(o);
    assert_eq!(code(o), status, "exit status; stderr:\n{err}");
    for s in says {
        assert!(err.contains(s), "stderr lacks `{s}`:\n{err}");
    }
}
