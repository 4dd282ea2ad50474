//! `fxrun`: batches of still images (`-i photos/ -o out/`, `-i 'photos/*.jpg'`,
//! `-i a.jpg b.png -o out/`), and the same-size check of temporal sequences.
//!
//! What is a batch: an effect that reads no other frame (no `IN[±n]`, no feedback) on
//! a folder, a wildcard pattern, or several inputs, written to a folder, a numbered
//! pattern or (one image) a file. A numbered input pattern (`in/%04d.png`), a stream,
//! a temporal effect, or the sequence options (`--frames`, `--warmup`, `--rate`,
//! `--fps`) make it a sequence instead (`sequence.rs`).

use super::*;
use fxgraph::app::{run_batch, BatchItem, BatchOptions, Device};
use fxgraph::io::FileFormat;
use std::collections::HashMap;
use std::path::Path;

/// Runs the command as a batch when it is one; `Ok(false)`: it is a single image or a
/// sequence, for the caller to run.
pub(crate) fn try_run_batch(cli: &Cli, kept: &mut Option<Engine>) -> Result<bool, Fail> {
    let Some(output) = &cli.output else {
        return Ok(false);
    };
    if cli.input.is_empty() {
        return Ok(false);
    }
    let ospec = SequenceSpec::parse_output(&output.to_string_lossy());
    let specs: Vec<SequenceSpec> = cli
        .input
        .iter()
        .map(|i| SequenceSpec::parse_input(&i.to_string_lossy()))
        .collect();
    if !is_batch_shape(cli, &specs, &ospec, output)? {
        return Ok(false);
    }
    // A batch reads and writes image files: no stream colour options apply.
    super::streams::check_color_options(cli, false, false)?;
    let mut effect = Effect::compile_overrides(&cli.effects, cli.set.clone())?;
    let g = &effect.graph;
    if g.history > 0 || g.latency > 0 || g.has_feedback() {
        if specs.len() == 1 {
            return Ok(false); // a sequence (its frames must have one size: check_same_size)
        }
        return Err(rejected(
            "this effect reads other frames (IN[-n], IN[+n] or feedback): give its frames as one folder or pattern, not as several -i",
        ));
    }
    let inputs = collect_inputs(cli, &specs)?;
    let mut items = name_outputs(cli, &inputs, &ospec)?;
    check_outputs(&items)?;
    if cli.skip_existing {
        items.retain(|it| std::fs::symlink_metadata(&it.output).is_err());
        if items.is_empty() {
            eprintln!("fxrun: every output exists already (--skip-existing)");
            return Ok(true);
        }
    }
    clean_output_dirs(&items);
    run(cli, &mut effect, &items, kept).map(|_| true)
}

/// Whether the inputs and the output make a batch: one folder or wildcard pattern
/// (without the sequence options or a stream output), or one image into a folder; or
/// several inputs, refused when one is a stream or pattern, with the sequence options
/// or with a stream output. `Ok(false)`: a single image or a sequence.
fn is_batch_shape(
    cli: &Cli,
    specs: &[SequenceSpec],
    ospec: &SequenceSpec,
    output: &Path,
) -> Result<bool, Fail> {
    let sequence_options =
        cli.frames.is_some() || cli.warmup > 0 || cli.rate != 1 || cli.fps.is_some();
    if let [spec] = specs {
        match spec {
            SequenceSpec::Dir(_) | SequenceSpec::Glob(_) => {
                if sequence_options || ospec.is_stream() {
                    return Ok(false);
                }
            }
            SequenceSpec::Single(_) if matches!(ospec, SequenceSpec::Dir(_)) => {}
            _ => return Ok(false),
        }
    } else {
        for (spec, arg) in specs.iter().zip(&cli.input) {
            if spec.is_stream() || matches!(spec, SequenceSpec::Pattern { .. }) {
                return Err(rejected(format!(
                    "-i {}: a stream or a numbered pattern is a sequence of its own; it cannot be one of several inputs",
                    arg.display()
                )));
            }
        }
        if sequence_options {
            return Err(rejected(
                "--frames, --warmup, --rate and --fps are for sequences (one -i pattern, folder or stream), not for several inputs",
            ));
        }
        if ospec.is_stream() {
            return Err(rejected(format!(
                "-o {} writes one stream: give its frames as one -i pattern or folder",
                output.display()
            )));
        }
    }
    Ok(true)
}

/// Removes the temporaries an interrupted run left in the output folders.
fn clean_output_dirs(items: &[BatchItem]) {
    let mut dirs: Vec<&Path> = items.iter().filter_map(|it| it.output.parent()).collect();
    dirs.sort();
    dirs.dedup();
    for d in dirs {
        let d = if d.as_os_str().is_empty() {
            Path::new(".")
        } else {
            d
        };
        let _ = fxgraph::io::sequence::remove_stale_temporaries(d);
    }
}

/// The input files, numbered: a single folder or wildcard pattern as a sequence numbers
/// its files (the numbers in the names when every name has a distinct one, else the
/// position in name order), several inputs by position from 0. Processed in name order
/// (a single folder or pattern) or in the order given.
pub(crate) fn collect_inputs(
    cli: &Cli,
    specs: &[SequenceSpec],
) -> Result<Vec<(u64, PathBuf)>, Fail> {
    let mut out: Vec<(u64, PathBuf)> = Vec::new();
    for (spec, arg) in specs.iter().zip(&cli.input) {
        match spec {
            SequenceSpec::Dir(dir) => {
                if cli.verbose {
                    note_skipped_files(dir);
                }
                let seq = InputSequence::open(spec).map_err(RunError::from)?;
                out.extend(seq.frames);
            }
            SequenceSpec::Glob(_) => {
                let seq = InputSequence::open(spec).map_err(RunError::from)?;
                for (n, p) in seq.frames {
                    if FileFormat::from_path(&p).is_some() {
                        out.push((n, p));
                    } else if cli.verbose {
                        eprintln!("fxrun: note: skipped {} (not an image file)", p.display());
                    }
                }
            }
            SequenceSpec::Single(_) => {
                if effect_after_input(arg) {
                    return Err(rejected(format!(
                        "-i {}: no such file; it looks like an effect: effects go before -i (fxrun EFFECT... -i INPUT... -o OUTPUT)",
                        arg.display()
                    )));
                }
                let seq = InputSequence::open(spec).map_err(RunError::from)?;
                out.extend(seq.frames);
            }
            _ => unreachable!("streams and patterns are refused above"),
        }
    }
    if specs.len() == 1 {
        out.sort_by(|a, b| a.1.file_name().cmp(&b.1.file_name()));
    } else {
        for (i, f) in out.iter_mut().enumerate() {
            f.0 = i as u64;
        }
    }
    if out.is_empty() {
        return Err(rejected(format!(
            "{}: no image files",
            cli.input[0].display()
        )));
    }
    Ok(out)
}

/// A missing input that is surely an effect given after `-i` (which takes every value
/// up to the next option).
pub(crate) fn effect_after_input(arg: &Path) -> bool {
    if std::fs::symlink_metadata(arg).is_ok() {
        return false;
    }
    let s = arg.to_string_lossy();
    s.ends_with(".fx")
        || library::builtin_effects()
            .iter()
            .any(|(name, _)| name.as_str() == s)
}

/// `-v`: the files of an input folder that are not images.
fn note_skipped_files(dir: &Path) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut names: Vec<PathBuf> = rd
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_file() && FileFormat::from_path(p).is_none())
        .filter(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        })
        .collect();
    names.sort();
    for p in names {
        eprintln!("fxrun: note: skipped {} (not an image file)", p.display());
    }
}

/// The output of each input: `-o DIR` keeps the input's file stem and extension (the
/// extension `--format` names instead, when given); a pattern numbers them; a file name
/// takes one image.
fn name_outputs(
    cli: &Cli,
    inputs: &[(u64, PathBuf)],
    ospec: &SequenceSpec,
) -> Result<Vec<BatchItem>, Fail> {
    let format = output_extension(cli)?;
    let in_dir = |dir: &Path| outputs_in_dir(dir, inputs, format.as_deref());
    let own_extension = || {
        rejected(
            "--format sets the format of -o DIR outputs; a pattern or a file name has its own extension",
        )
    };
    match ospec {
        SequenceSpec::Dir(dir) => in_dir(dir),
        SequenceSpec::Pattern { .. } => {
            if format.is_some() {
                return Err(own_extension());
            }
            let pattern = OutputPattern::new(ospec).map_err(RunError::from)?;
            Ok(inputs
                .iter()
                .map(|(n, p)| BatchItem {
                    input: p.clone(),
                    output: pattern.path_for(*n),
                })
                .collect())
        }
        SequenceSpec::Single(file) if FileFormat::from_path(file).is_some() => {
            if format.is_some() {
                return Err(own_extension());
            }
            match inputs {
                [(_, p)] => Ok(vec![BatchItem {
                    input: p.clone(),
                    output: file.clone(),
                }]),
                _ => Err(rejected(format!(
                    "-o {}: {} input images need an output folder (-o DIR/) or a numbered pattern (-o 'out/%04d.png')",
                    file.display(),
                    inputs.len()
                ))),
            }
        }
        // A name without an extension: a folder to create.
        SequenceSpec::Single(dir) if dir.extension().is_none() => in_dir(dir),
        other => Err(rejected(format!(
            "-o {}: a batch writes to a folder, a numbered pattern or (one image) a file",
            other.display_path().display()
        ))),
    }
}

/// `--format EXT`: the extension of `-o DIR` outputs, refused when unknown.
fn output_extension(cli: &Cli) -> Result<Option<String>, Fail> {
    Ok(match &cli.format {
        Some(ext) => {
            let ext = ext.trim_start_matches('.');
            if FileFormat::from_extension(ext).is_none() {
                return Err(rejected(format!(
                    "--format {ext}: unknown image file extension (use png, jpg, exr, tif, ...)"
                )));
            }
            Some(ext.to_string())
        }
        None => None,
    })
}

/// The outputs in `dir` (created): each input's file stem with its extension, or
/// `format`.
fn outputs_in_dir(
    dir: &Path,
    inputs: &[(u64, PathBuf)],
    format: Option<&str>,
) -> Result<Vec<BatchItem>, Fail> {
    std::fs::create_dir_all(dir).map_err(|e| {
        RunError::from(fxgraph::io::IoError::Io {
            path: dir.to_path_buf(),
            source: e,
        })
    })?;
    Ok(inputs
        .iter()
        .map(|(_, p)| {
            let stem = p.file_stem().unwrap_or_default().to_string_lossy();
            let ext = match format {
                Some(f) => f.to_string(),
                None => p.extension().unwrap_or_default().to_string_lossy().into(),
            };
            BatchItem {
                input: p.clone(),
                output: dir.join(format!("{stem}.{ext}")),
            }
        })
        .collect())
}

/// Refuses a batch that would write two images to one file, or over one of its inputs.
pub(crate) fn check_outputs(items: &[BatchItem]) -> Result<(), Fail> {
    let canonical = |p: &Path| -> PathBuf {
        if let Ok(c) = p.canonicalize() {
            return c;
        }
        let parent = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        match (parent.canonicalize(), p.file_name()) {
            (Ok(d), Some(n)) => d.join(n),
            _ => p.to_path_buf(),
        }
    };
    let inputs: HashMap<PathBuf, &Path> = items
        .iter()
        .map(|it| (canonical(&it.input), it.input.as_path()))
        .collect();
    let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
    for it in items {
        let out = canonical(&it.output);
        if let Some(input) = inputs.get(&out) {
            return Err(rejected(format!(
                "{}: writing this output would replace the input {}; choose another output folder",
                it.output.display(),
                input.display()
            )));
        }
        if let Some(first) = seen.insert(out, &it.input) {
            return Err(rejected(format!(
                "{} and {} would both be written to {}; use a numbered pattern output (-o 'out/%04d.png')",
                first.display(),
                it.input.display(),
                it.output.display()
            )));
        }
    }
    Ok(())
}

/// The device is left in `kept` (see [`crate::teardown`]).
fn run(
    cli: &Cli,
    effect: &mut Effect,
    items: &[BatchItem],
    kept: &mut Option<Engine>,
) -> Result<(), Fail> {
    let stop = stop_flag();
    let adapter = adapter_choice(&cli.adapter);
    let opts = BatchOptions {
        bit_depth: cli.bit_depth,
        assume_linear: cli.assume_linear,
        keep_going: cli.keep_going,
        queue: cli.queue.max(1),
        timings: cli.timings || cli.timings_json.is_some(),
        viewport: crate::viewport_of(cli)?,
        aux: crate::aux_images(cli)?,
    };
    let progress = ProgressLine::new("images");
    // The device is created while the first image decodes.
    let device = Device::kept(kept, &adapter);
    let result = run_batch(
        device,
        effect,
        items,
        &opts,
        stop.clone(),
        progress.callback(),
    );
    progress.finish();
    print_diagnostics(cli, effect);
    let report = result?;
    finish_report(cli, &report)?;
    if report.interrupted {
        return Err(Fail {
            code: 130,
            message: format!(
                "interrupted: {} of {} images written, each complete ({}); rerun with --skip-existing to do the other {}",
                report.done.len(),
                items.len(),
                if cli.verbose { "listed above" } else { "-v lists them" },
                items.len().saturating_sub(report.done.len())
            ),
        });
    }
    match report.failed.iter().map(|f| exit_code(&f.error)).max() {
        Some(code) => Err(Fail {
            code,
            message: String::new(),
        }),
        None => Ok(()),
    }
}

/// A sequence's frames must all have one size (a temporal effect reads several at
/// once): checked from the headers before any frame is decoded or written. The error
/// names the first frame whose size differs.
pub(crate) fn check_same_size(frames: &[(u64, PathBuf)]) -> Result<(), Fail> {
    let Some((_, first)) = frames.first() else {
        return Ok(());
    };
    let size = fxgraph::io::image_file_dimensions(first).map_err(RunError::from)?;
    for (_, p) in &frames[1..] {
        let s = fxgraph::io::image_file_dimensions(p).map_err(RunError::from)?;
        if s != size {
            return Err(rejected(format!(
                "{}: the frame is {}x{}, the first frame ({}) is {}x{}: the frames of a sequence must have one size (the effect reads several frames at once); an effect that reads one frame runs on images of any size",
                p.display(),
                s.0,
                s.1,
                first.display(),
                size.0,
                size.1
            )));
        }
    }
    Ok(())
}
