//! Running the real `fxrun` binary from a test, and what the tests of it check
//! after a run: the exit status, the message, the files left in a folder.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// `fxrun ARGS` in the repository's root.
pub fn fxrun(args: &[&str]) -> Output {
    fxrun_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// `fxrun` with the command line `line`: its words split at spaces, each `{}`
/// replaced by the next of `paths` (as one argument, whatever it holds).
pub fn fxrun_line(line: &str, paths: &[&Path]) -> Output {
    let mut paths = paths.iter();
    let args: Vec<&OsStr> = line
        .split_whitespace()
        .map(|w| match w {
            "{}" => paths.next().expect("a path for each {}").as_os_str(),
            w => OsStr::new(w),
        })
        .collect();
    assert!(paths.next().is_none(), "more paths than {{}} in `{line}`");
    command(args).output().expect("run fxrun")
}

/// `fxrun ARGS` in `dir`.
pub fn fxrun_in(dir: &Path, args: &[&str]) -> Output {
    command(args).current_dir(dir).output().expect("run fxrun")
}

/// `fxrun` with the command line `line` (its words split at spaces) in `dir`.
pub fn fxrun_line_in(dir: &Path, line: &str) -> Output {
    fxrun_in(dir, &line.split_whitespace().collect::<Vec<_>>())
}

/// [`fxrun_line_in`], which must succeed (exit 0; its stderr shown if not).
#[track_caller]
pub fn succeeds_in(dir: &Path, line: &str) -> Output {
    let o = fxrun_line_in(dir, line);
    exits(&o, 0);
    o
}

/// `fxrun ARGS` in the repository's root, reading `stdin` (nothing: an empty,
/// closed stdin).
pub fn fxrun_stdin(args: &[&str], stdin: Option<&[u8]>) -> Output {
    feed(command(args), stdin)
}

/// `fxrun ARGS` in `dir`, with extra environment variables (a `PATH` without
/// ffmpeg) and `stdin` as its standard input.
pub fn fxrun_with(dir: &Path, args: &[&str], env: &[(&str, &str)], stdin: &[u8]) -> Output {
    let mut c = command(args);
    c.current_dir(dir).envs(env.iter().copied());
    feed(c, Some(stdin))
}

/// Run `cmd` with `stdin` written to its standard input (from a thread, so that a
/// large input cannot block against its output) and its output collected.
fn feed(mut cmd: Command, stdin: Option<&[u8]>) -> Output {
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run fxrun");
    let mut child_stdin = child.stdin.take().unwrap();
    let data = stdin.map(|d| d.to_vec());
    let writer = std::thread::spawn(move || {
        use std::io::Write;
        if let Some(d) = data {
            let _ = child_stdin.write_all(&d);
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    out
}

/// The `fxrun ARGS` command, in the repository's root, not started.
pub fn command<I: AsRef<OsStr>>(args: impl IntoIterator<Item = I>) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_fxrun"));
    c.args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir());
    c
}

/// `fxrun EFFECT -i INPUT -o OUTPUT EXTRA...` in the repository's root.
pub fn apply(
    effect: impl AsRef<OsStr>,
    input: impl AsRef<OsStr>,
    output: impl AsRef<OsStr>,
    extra: &[&str],
) -> Output {
    let mut args = vec![
        effect.as_ref(),
        OsStr::new("-i"),
        input.as_ref(),
        OsStr::new("-o"),
        output.as_ref(),
    ];
    args.extend(extra.iter().map(OsStr::new));
    command(args).output().expect("run fxrun")
}

/// A path as a command-line argument (test paths are UTF-8).
pub fn arg(p: &Path) -> &str {
    p.to_str().expect("UTF-8 test path")
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

/// Asserts that the run exited with `expected` (its stderr shown if not) and
/// returns its stderr.
#[track_caller]
pub fn exits(o: &Output, expected: i32) -> String {
    let e = stderr(o);
    assert_eq!(code(o), expected, "{e}");
    e
}

/// Asserts that the run exited with `expected` and that its stderr contains every
/// one of `needles`; returns its stderr.
#[track_caller]
pub fn exits_with(o: &Output, expected: i32, needles: &[&str]) -> String {
    let e = exits(o, expected);
    for n in needles {
        assert!(e.contains(n), "no `{n}` in:\n{e}");
    }
    e
}

/// The names of the files in `dir`, sorted (temporaries included, so that a stray
/// one shows); none when `dir` does not exist.
pub fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Asserts that no temporary file of an atomic write (`*.fxtmp-*`) is left in `dir`.
#[track_caller]
pub fn assert_no_temporaries(dir: &Path) {
    let names = names(dir);
    assert!(names.iter().all(|n| !n.contains("fxtmp")), "{names:?}");
}

/// The names and contents of the files in `dir`, sorted by name.
pub fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    names(dir)
        .into_iter()
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

/// Writes `img` to `path` (format from the extension).
pub fn save(path: &Path, img: &fxgraph::io::Image) {
    fxgraph::io::save_image(
        path,
        img.width,
        img.height,
        &img.pixels,
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

/// `dir/in.png`: the 48x32 test pattern (super::pattern_u8).
pub fn input_png(dir: &Path) -> PathBuf {
    let p = dir.join("in.png");
    save(&p, &super::pattern_u8(48, 32));
    p
}

/// Writes the first `num / den` of the bytes of `src` to `dst` (a truncated file).
pub fn cut(src: &Path, dst: &Path, num: usize, den: usize) {
    let bytes = std::fs::read(src).unwrap();
    std::fs::write(dst, &bytes[..bytes.len() * num / den]).unwrap();
}

/// Writes `text` to `dir/name` and returns its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// An effect `NAME.fx` in `dir` with its shader `SHADER.wgsl` beside it; returns the
/// effect's path as an argument.
pub fn write_effect(dir: &Path, name: &str, fx: &str, shader: (&str, &str)) -> String {
    std::fs::write(dir.join(format!("{}.wgsl", shader.0)), shader.1).unwrap();
    let p = dir.join(format!("{name}.fx"));
    std::fs::write(&p, fx).unwrap();
    p.display().to_string()
}

/// The bytes of the file at `path` (panics naming it).
pub fn read(path: impl AsRef<Path>) -> Vec<u8> {
    let p = path.as_ref();
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Asserts that the files at `a` and `b` hold the same bytes.
#[track_caller]
pub fn assert_same_file(a: impl AsRef<Path>, b: impl AsRef<Path>) {
    let (a, b) = (a.as_ref(), b.as_ref());
    assert!(
        read(a) == read(b),
        "{} and {} differ",
        a.display(),
        b.display()
    );
}
