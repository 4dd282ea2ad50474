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
//! Input folders are hot folders: with `-i DIR` or `-i 'DIR/*.jpg'` the folder is
//! watched too, and an image that appears or changes there (by modification time
//! or length) is processed. A batch whose outputs keep their input's name (`-o DIR`)
//! processes just the new and changed images; a sequence (a temporal effect, or a
//! numbered output pattern) is re-run whole. A file still being copied fails to
//! decode, is reported, and is processed again when its copy completes (its length
//! or time changes). The output folder may not be an input folder (every output
//! would be a new input).
//!
//! [`SourceMap::disk_paths`]: fxgraph::script::SourceMap::disk_paths

use super::*;
use fxgraph::io::sequence::SequenceSpec;
use notify::{EventKind, RecursiveMode, Watcher as _};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant, SystemTime};

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
    let stream = |p: &PathBuf| {
        p.as_os_str() == "-"
            || fxgraph::io::sequence::is_y4m_path(p)
            || fxgraph::io::video::is_video_path(p)
    };
    if cli.input.iter().any(stream) || cli.output.as_ref().is_some_and(stream) {
        return Some("--watch cannot re-run a y4m or video stream (-i -, -o -, .y4m, .mp4, ...): give image files");
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
    let mut hot = HotFolders::new(cli)?;
    let mut job = cli.clone();
    loop {
        // Each run creates its device and drops it (the watch goes on).
        let result = run_job(&job, &mut None);
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
        watch_new_dirs(&mut watcher, &mut dirs, &files, hot.as_ref());
        announce_watching(&files, hot.as_ref());
        job = match next_job(cli, &rx, &files, &mut hot, &stop) {
            Some(next) => next,
            None => return Ok(()),
        };
    }
}

/// Watches the folders of `files` and the hot input folders not watched yet (added to
/// `dirs`); a folder that cannot be watched is a warning.
fn watch_new_dirs(
    watcher: &mut notify::RecommendedWatcher,
    dirs: &mut HashSet<PathBuf>,
    files: &HashSet<PathBuf>,
    hot: Option<&HotFolders>,
) {
    let watch_dirs = files
        .iter()
        .filter_map(|f| f.parent().map(Path::to_path_buf))
        .chain(hot.iter().flat_map(|h| h.dirs.clone()));
    for dir in watch_dirs.collect::<Vec<_>>() {
        if dirs.insert(dir.clone()) {
            if let Err(e) = watcher.watch(&dir, RecursiveMode::NonRecursive) {
                eprintln!("fxrun: warning: --watch: {}: {e}", dir.display());
            }
        }
    }
}

/// Says what is watched.
fn announce_watching(files: &HashSet<PathBuf>, hot: Option<&HotFolders>) {
    match hot {
        Some(h) => eprintln!(
            "fxrun: watching {} files and {} input folder(s) for changes (Ctrl-C ends)",
            files.len(),
            h.dirs.len()
        ),
        None => eprintln!(
            "fxrun: watching {} files for changes (Ctrl-C ends)",
            files.len()
        ),
    }
}

/// Waits for the next change and says what to run then: the whole job again (the
/// effect or a watched file changed), or only the new or changed inputs of hot folders
/// whose output names are kept; `None` when stopped (Ctrl-C).
fn next_job(
    cli: &Cli,
    rx: &Receiver<notify::Result<notify::Event>>,
    files: &HashSet<PathBuf>,
    hot: &mut Option<HotFolders>,
    stop: &AtomicBool,
) -> Option<Cli> {
    loop {
        let hot_dirs: Vec<PathBuf> = hot.iter().flat_map(|h| h.dirs.clone()).collect();
        match wait_for_change(rx, files, &hot_dirs, stop) {
            Change::Stop => return None,
            Change::Script => {
                if let Some(h) = hot {
                    h.refresh(cli);
                }
                return Some(cli.clone());
            }
            Change::Inputs => {
                let Some(h) = hot.as_mut() else { continue };
                let changed = h.refresh(cli);
                if changed.is_empty() {
                    continue;
                }
                eprintln!(
                    "fxrun: {} new or changed input(s): {}",
                    changed.len(),
                    changed
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                if !h.names_kept {
                    return Some(cli.clone());
                }
                let mut sub = cli.clone();
                sub.input = changed;
                return Some(sub);
            }
        }
    }
}

/// The input folders of a batch or folder sequence, and what was in them.
struct HotFolders {
    /// Canonical folders.
    dirs: Vec<PathBuf>,
    /// Input images with their modification time and length at the last look.
    seen: HashMap<PathBuf, (Option<SystemTime>, u64)>,
    /// The outputs keep their inputs' names (`-o DIR`, an effect that reads no
    /// other frame): new inputs can be run alone.
    names_kept: bool,
}

impl HotFolders {
    /// None when no input is a folder or wildcard pattern.
    fn new(cli: &Cli) -> Result<Option<HotFolders>, Fail> {
        let mut dirs = Vec::new();
        for i in &cli.input {
            let dir = match SequenceSpec::parse_input(&i.to_string_lossy()) {
                SequenceSpec::Dir(d) => d,
                SequenceSpec::Glob(g) => match Path::new(&g).parent() {
                    Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                    _ => PathBuf::from("."),
                },
                _ => continue,
            };
            if let Ok(c) = std::fs::canonicalize(&dir) {
                dirs.push(c);
            }
        }
        if dirs.is_empty() {
            return Ok(None);
        }
        let out = cli
            .output
            .as_ref()
            .map(|o| SequenceSpec::parse_output(&o.to_string_lossy()));
        let out_dir = match &out {
            Some(SequenceSpec::Dir(d)) => std::fs::canonicalize(d).ok(),
            _ => None,
        };
        if out_dir.as_ref().is_some_and(|o| dirs.contains(o)) {
            return Err(rejected(
                "--watch: the output folder is an input folder, so every output would be a new input: write to another folder",
            ));
        }
        // A temporal effect makes a folder a sequence: re-run whole.
        let temporal = match compile(&fxgraph::lookup::DiskEffects::request(&cli.effects, &[])) {
            (Some(g), _, _) => g.history > 0 || g.latency > 0 || g.has_feedback(),
            _ => false,
        };
        let mut h = HotFolders {
            dirs,
            seen: HashMap::new(),
            // `-o DIR`, or a name without an extension (a folder the batch creates).
            names_kept: !temporal
                && match &out {
                    Some(SequenceSpec::Dir(_)) => true,
                    Some(SequenceSpec::Single(p)) => p.extension().is_none(),
                    _ => false,
                },
        };
        h.refresh(cli);
        Ok(Some(h))
    }

    /// Look again; the inputs that are new or changed since the last look.
    fn refresh(&mut self, cli: &Cli) -> Vec<PathBuf> {
        let specs: Vec<SequenceSpec> = cli
            .input
            .iter()
            .map(|i| SequenceSpec::parse_input(&i.to_string_lossy()))
            .collect();
        let inputs = collect_inputs(cli, &specs).unwrap_or_default();
        let mut changed = Vec::new();
        let mut now = HashMap::new();
        for (_, p) in inputs {
            let Ok(m) = std::fs::metadata(&p) else {
                continue;
            };
            let stamp = (m.modified().ok(), m.len());
            if self.seen.get(&p) != Some(&stamp) {
                changed.push(p.clone());
            }
            now.insert(p, stamp);
        }
        self.seen = now;
        changed
    }
}

/// What [`wait_for_change`] saw.
pub(crate) enum Change {
    /// Ctrl-C.
    Stop,
    /// An effect, include or shader (or a single input image) changed.
    Script,
    /// Something changed in an input folder.
    Inputs,
}

/// Waits for a change of one of `files` or in one of `hot_dirs`, then lets a burst
/// of events settle (an editor's save, or a copy, is several). Also `--view`'s hot
/// reload (`view/reload.rs`).
pub(crate) fn wait_for_change(
    rx: &Receiver<notify::Result<notify::Event>>,
    files: &HashSet<PathBuf>,
    hot_dirs: &[PathBuf],
    stop: &AtomicBool,
) -> Change {
    let classify = |ev: &notify::Event| {
        if matches!(ev.kind, EventKind::Access(_)) {
            None
        } else if ev.paths.iter().any(|p| files.contains(p)) {
            Some(Change::Script)
        } else if ev
            .paths
            .iter()
            .any(|p| p.parent().is_some_and(|d| hot_dirs.iter().any(|h| h == d)))
        {
            Some(Change::Inputs)
        } else {
            None
        }
    };
    let mut seen = loop {
        if stop.load(Ordering::SeqCst) {
            return Change::Stop;
        }
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(Ok(ev)) => {
                if let Some(c) = classify(&ev) {
                    break c;
                }
            }
            Ok(Err(_)) | Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return Change::Stop,
        }
    };
    // Debounce: until 150 ms pass without an event (at most 2 s). A script change
    // among the events wins (it re-runs everything).
    let start = Instant::now();
    while let Ok(ev) = rx.recv_timeout(Duration::from_millis(150)) {
        if let Ok(ev) = ev {
            if let Some(Change::Script) = classify(&ev) {
                seen = Change::Script;
            }
        }
        if start.elapsed() > Duration::from_secs(2) {
            break;
        }
    }
    seen
}

/// The files a run reads that a change should re-run it for, as absolute paths with
/// canonical folders (as the events name them). The output is never among them.
pub(crate) fn watched_files(cli: &Cli) -> Vec<PathBuf> {
    let req = fxgraph::lookup::DiskEffects::request_with(&cli.effects, cli.set.clone());
    let (graph, _, mut sources) = compile(&req);
    if let Some(graph) = graph {
        // The shaders the plan's passes use (no GPU needed), at the input's size.
        let (w, h) = match cli.input.as_slice() {
            [i] => fxgraph::io::image_file_dimensions(i).unwrap_or((1920, 1080)),
            _ => (1920, 1080),
        };
        let desc = planning_input(cli, w, h);
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
    paths.extend(preset_files(cli));
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

/// The slang presets among the effects, with their shaders and LUTs (the effect
/// they are lowered to lies in the temporary folder; an edit of these re-lowers
/// it, see `slang::lower_preset`).
#[cfg(feature = "slang")]
fn preset_files(cli: &Cli) -> Vec<PathBuf> {
    cli.effects
        .iter()
        .filter(|e| fxgraph::slang::is_preset(e))
        .flat_map(|e| {
            fxgraph::slang::preset_files(Path::new(e)).unwrap_or_else(|_| vec![PathBuf::from(e)])
        })
        .collect()
}

#[cfg(not(feature = "slang"))]
fn preset_files(_: &Cli) -> Vec<PathBuf> {
    Vec::new()
}

/// `path` with its folder made canonical (the file itself may not exist yet).
fn absolute(path: &Path) -> Option<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(path.file_name()?))
}
