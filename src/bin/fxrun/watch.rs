//! `fxrun ... --watch`: after an image, batch or file-sequence run, re-run it each
//! time the effect or one of the files it read changes (hot reload).
//!
//! Watched: the effect files, their `INCLUDE`s, the pass shaders and their
//! `#include`s (the files the compilation read from disk, [`SourceMap::disk_paths`];
//! built-in files are not watched), and for a single image its input and `--aux`
//! images. The parent folders are watched (editors save by rename) and the events
//! filtered by path. A script or shader error is printed and the watch goes on;
//! Ctrl-C ends it with status 0 (130 when it interrupts a batch or sequence run).
//!
//! [`SourceMap::disk_paths`]: fxgraph::script::SourceMap::disk_paths

use super::*;
use notify::{EventKind, RecursiveMode, Watcher as _};
use std::collections::HashSet;
use std::path::Path;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// Why `--watch` cannot be used with these options, if so.
fn refusal(cli: &Cli) -> Option<&'static str> {
    if cli.check || cli.plan || cli.dot.is_some() || cli.describe || cli.list || cli.adapters {
        return Some("--watch re-runs image, batch and file-sequence runs; it does not take --check, --plan, --dot, --describe, --list or --adapters");
    }
    if cli.scene.is_some() || cli.describe_materials || cli.effects.is_empty() {
        return Some(
            "--watch re-runs image, batch and file-sequence runs; a --scene render is not watched",
        );
    }
    let stream = |p: &PathBuf| p.as_os_str() == "-";
    if cli.input.iter().any(stream) || cli.output.as_ref().is_some_and(stream) {
        return Some("--watch cannot re-run a y4m stream (-i - or -o -): give files");
    }
    if cli.skip_existing {
        return Some("--watch with --skip-existing would skip every output after the first run");
    }
    None
}

/// The `--watch` loop: run, then wait for a change of a watched file, and again.
pub(crate) fn run_watch(cli: &Cli) -> Result<(), Fail> {
    if let Some(why) = refusal(cli) {
        return Err(rejected(why));
    }
    let stop = stop_flag();
    let (tx, rx) = std::sync::mpsc::channel();
    let mut watcher = notify::recommended_watcher(tx).map_err(|e| Fail {
        code: 2,
        message: format!("--watch: {e}"),
    })?;
    let mut dirs: HashSet<PathBuf> = HashSet::new();
    // A union over the runs: an effect that does not compile keeps the files of
    // the runs before it.
    let mut files: HashSet<PathBuf> = HashSet::new();
    loop {
        let result = run_job(cli);
        if let Err(f) = &result {
            print_fail(f);
        }
        if stop.load(Ordering::SeqCst) {
            return match result {
                Err(f) if f.code == 130 => Err(Fail {
                    code: 130,
                    message: String::new(),
                }),
                _ => Ok(()),
            };
        }
        files.extend(watched_files(cli));
        for f in &files {
            let Some(dir) = f.parent() else { continue };
            if dirs.insert(dir.to_path_buf()) {
                if let Err(e) = watcher.watch(dir, RecursiveMode::NonRecursive) {
                    eprintln!("fxrun: warning: --watch: {}: {e}", dir.display());
                }
            }
        }
        eprintln!(
            "fxrun: watching {} files for changes (Ctrl-C ends)",
            files.len()
        );
        if !wait_for_change(&rx, &files, &stop) {
            return Ok(());
        }
    }
}

/// Waits for a change of one of `files`, then lets a burst of events settle (an
/// editor's save is several). False: Ctrl-C.
fn wait_for_change(
    rx: &Receiver<notify::Result<notify::Event>>,
    files: &HashSet<PathBuf>,
    stop: &AtomicBool,
) -> bool {
    let relevant = |ev: &notify::Event| {
        !matches!(ev.kind, EventKind::Access(_)) && ev.paths.iter().any(|p| files.contains(p))
    };
    loop {
        if stop.load(Ordering::SeqCst) {
            return false;
        }
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(Ok(ev)) if relevant(&ev) => break,
            Ok(_) | Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return false,
        }
    }
    // Debounce: until 150 ms pass without an event (at most 2 s).
    let start = Instant::now();
    while rx.recv_timeout(Duration::from_millis(150)).is_ok() {
        if start.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    true
}

/// The files a run reads that a change should re-run it for, as absolute paths with
/// canonical folders (as the events name them). The output is never among them.
fn watched_files(cli: &Cli) -> Vec<PathBuf> {
    let req = CompileRequest {
        effects: cli.effects.clone(),
        overrides: cli
            .set
            .iter()
            .map(|a| Override { arg: a.clone() })
            .collect(),
        search_dirs: Vec::new(),
    };
    let (graph, _, mut sources) = compile(&req);
    if let Some(graph) = graph {
        // The shaders the plan's passes use (no GPU needed), at the input's size.
        let (w, h) = match cli.input.as_slice() {
            [i] => fxgraph::io::image_file_dimensions(i).unwrap_or((1920, 1080)),
            _ => (1920, 1080),
        };
        let mut desc =
            InputDesc::rgba8_srgb(w, h).with_aux(&fxgraph::deferred::published_aux(true));
        for a in &cli.aux {
            let name = a.split_once('=').map(|(n, _)| n).unwrap_or(a);
            desc.aux.retain(|(n, _)| n != name);
            desc.aux
                .push((name.to_string(), fxgraph::script::types::Format::Rgba8Srgb));
        }
        if let Ok((p, _)) = plan(&graph, &desc, &PlanOptions::default()) {
            let _ = fxgraph::shader::load_plan_shaders(&graph, &p, &mut sources, &[]);
        }
    }
    let mut paths = sources.disk_paths();
    // An effect file that could not be read yet (a typo being fixed).
    paths.extend(
        cli.effects
            .iter()
            .map(PathBuf::from)
            .filter(|p| p.extension().is_some_and(|e| e == "fx")),
    );
    if let [input] = cli.input.as_slice() {
        if input.is_file() {
            paths.push(input.clone());
        }
    }
    paths.extend(
        cli.aux
            .iter()
            .filter_map(|a| a.split_once('=').map(|(_, f)| PathBuf::from(f))),
    );
    let output = cli.output.as_deref().and_then(absolute);
    let mut out: Vec<PathBuf> = Vec::new();
    for p in paths {
        let mut both = vec![absolute(&p)];
        // A symbolic link: its target too.
        both.push(std::fs::canonicalize(&p).ok());
        for a in both.into_iter().flatten() {
            if Some(&a) != output.as_ref() && !out.contains(&a) {
                out.push(a);
            }
        }
    }
    out
}

/// `path` with its folder made canonical (the file itself may not exist yet).
fn absolute(path: &Path) -> Option<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(path.file_name()?))
}
