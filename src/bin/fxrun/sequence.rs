//! `fxrun`: frame sequences and y4m or video streams (`-i 'in/%04d.png'`, `-i -`,
//! `-i in.mkv`), the progress line.

use super::*;
use fxgraph::app::{BatchItem, Change};
use fxgraph::io::sequence::FrameRange;
use fxgraph::io::video::{HdrMetadata, VideoInfo};
use fxgraph::io::y4m::{Y4mHeader, YuvConversion};
use std::collections::HashMap;
use streams::{
    check_interrupted, open_input, open_stream_output, skip_whole_file, stream_input,
    stream_output, StreamPlan,
};

/// `fxrun EFFECT -i 'in/%04d.png' -o 'out/%04d.png'`, `-i - -o -` (y4m streams),
/// `-i in.y4m -o out.mp4` (files).
pub(crate) fn run_sequence_cli(
    cli: &Cli,
    ispec: SequenceSpec,
    ospec: SequenceSpec,
    kept: &mut Option<Engine>,
) -> Result<(), Fail> {
    if cli.rate == 0 || cli.rate > 4 {
        return Err(rejected(format!("--rate {}: expected 1 to 4", cli.rate)));
    }
    streams::check_color_options(cli, ispec.is_stream(), ospec.is_stream())?;
    // Ctrl-C stops the run from here on (the ffmpeg children started below are in
    // their own process group: fxrun ends them).
    let stop = stop_flag();
    let mut effect = Effect::compile_overrides(&cli.effects, cli.set.clone())?;
    print_diagnostics(cli, &effect);
    let range = match &cli.frames {
        Some(f) => Some(parse_frames(f).map_err(|e| rejected(format!("--frames {f}: {e}")))?),
        None => None,
    };
    let fps = checked_fps(cli)?;
    check_output_is_not_input(&ispec, &ospec)?;
    // A whole y4m or video file is written or not: with --skip-existing, an existing
    // one is kept and the run skipped.
    if skip_whole_file(cli, &ospec) {
        return Ok(());
    }
    let Some(mut input) = open_sequence_source(cli, &ispec, &ospec, &effect, range, fps)? else {
        return Ok(());
    };
    let (sink, output_format) = open_sequence_sink(cli, &ospec, &mut input, &effect)?;
    if let Some(h) = &input.hdr_in {
        apply_hdr_tonemap(cli, &mut effect, h)?;
    }
    if let Some((h, _)) = &input.y4m_template {
        apply_input_field_order(&mut effect, h)?;
    }
    let opts = SequenceOptions {
        output_format,
        assume_linear: cli.assume_linear,
        rate: cli.rate,
        fps: input.fps,
        emit: input.emit,
        queue: cli.queue.max(1),
        timings: cli.timings || cli.timings_json.is_some(),
        ycbcr: cli
            .ycbcr
            .parse()
            .map_err(|e: String| rejected(format!("--ycbcr: {e}")))?,
        viewport: crate::viewport_of(cli)?,
        aux: crate::aux_images(cli)?,
    };
    let adapter = adapter_choice(&cli.adapter);
    let progress = ProgressLine::new("frames");
    // The device is created while the first frames decode.
    // The device is left in `kept` (see `crate::teardown`).
    let device = fxgraph::app::Device::kept(kept, &adapter);
    let result = run_sequence(
        device,
        &mut effect,
        input.source,
        sink,
        &opts,
        None,
        stop.clone(),
        progress.callback(),
    );
    progress.finish();
    let report = result?;
    finish_report(cli, &report)?;
    check_interrupted(&report, &ospec)
}

/// `--fps`, 25 when not given: refused unless above 0 and at most 1000.
fn checked_fps(cli: &Cli) -> Result<f64, Fail> {
    let fps = cli.fps.unwrap_or(25.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(rejected(format!(
            "--fps {fps}: expected a number above 0, at most 1000"
        )));
    }
    Ok(fps)
}

/// A y4m or video file read and written at once would be replaced by the output:
/// refused.
fn check_output_is_not_input(ispec: &SequenceSpec, ospec: &SequenceSpec) -> Result<(), Fail> {
    if let (
        SequenceSpec::Y4m(i) | SequenceSpec::Video(i),
        SequenceSpec::Y4m(o) | SequenceSpec::Video(o),
    ) = (ispec, ospec)
    {
        if let (Ok(a), Ok(b)) = (std::fs::canonicalize(i), std::fs::canonicalize(o)) {
            if a == b {
                return Err(rejected(format!(
                    "-o {}: the output would replace the input; write another file",
                    o.display()
                )));
            }
        }
    }
    Ok(())
}

/// The opened input of a sequence, and what the output and the effect take from it.
struct SequenceInput {
    source: Box<dyn FrameSource>,
    /// `--fps`, else a stream's own rate.
    fps: f64,
    /// A stream input's header and Y'CbCr conversion.
    y4m_template: Option<(Y4mHeader, YuvConversion)>,
    /// A video input's streams.
    video_in: Option<VideoInfo>,
    /// An HDR stream input's metadata.
    hdr_in: Option<HdrMetadata>,
    /// The frame numbers written (the slice, without its context frames).
    emit: Option<(u64, u64)>,
    /// `-o DIR` from files (one output per input frame): each frame's own file name.
    named: Option<HashMap<u64, PathBuf>>,
}

/// Source: files (with the context frames a slice needs) or a y4m or video stream.
/// `None` when there is nothing to do (every output exists, with --skip-existing).
fn open_sequence_source(
    cli: &Cli,
    ispec: &SequenceSpec,
    ospec: &SequenceSpec,
    effect: &Effect,
    range: Option<FrameRange>,
    fps: f64,
) -> Result<Option<SequenceInput>, Fail> {
    match ispec {
        SequenceSpec::Stdin | SequenceSpec::Y4m(_) | SequenceSpec::Video(_) => {
            open_stream_source(cli, ispec, effect, range, fps).map(Some)
        }
        SequenceSpec::Stdout => Err(rejected("`-` as an input reads stdin; use -i - ")),
        spec => open_files_source(cli, spec, ospec, effect, range, fps),
    }
}

/// A y4m or video stream as the source, skipping to the frames a slice needs.
fn open_stream_source(
    cli: &Cli,
    ispec: &SequenceSpec,
    effect: &Effect,
    range: Option<FrameRange>,
    fps: f64,
) -> Result<SequenceInput, Fail> {
    let (history, latency) = (effect.graph.history as u64, effect.graph.latency as u64);
    let input = stream_input(ispec).expect("a stream spec");
    let opened = open_input(cli, &input)?;
    let header = opened.header.clone();
    let fps = if cli.fps.is_none() && header.fps.1 > 0 {
        header.fps.0 as f64 / header.fps.1 as f64
    } else {
        fps
    };
    let y4m_template = Some((header, opened.conversion));
    let video_in = opened.video.clone();
    let hdr_in = opened.is_hdr().then(|| opened.hdr_metadata());
    let mut emit = None;
    let (skip, last) = match range {
        Some(r) => {
            emit = Some((r.start, r.end));
            (
                r.start.saturating_sub(history + cli.warmup),
                r.end.checked_add(latency),
            )
        }
        None => (0, None),
    };
    Ok(SequenceInput {
        source: opened.into_source(skip, last),
        fps,
        y4m_template,
        video_in,
        hdr_in,
        emit,
        named: None,
    })
}

/// Numbered image files as the source: the slice (`--frames`, after the outputs that
/// exist with --skip-existing) widened by the context frames the effect needs.
fn open_files_source(
    cli: &Cli,
    spec: &SequenceSpec,
    ospec: &SequenceSpec,
    effect: &Effect,
    range: Option<FrameRange>,
    fps: f64,
) -> Result<Option<SequenceInput>, Fail> {
    let (history, latency) = (effect.graph.history as u64, effect.graph.latency as u64);
    let seq = InputSequence::open(spec).map_err(RunError::from)?;
    let all = &seq.frames;
    let named = match (ospec, cli.rate) {
        (SequenceSpec::Dir(dir), 1) => Some(named_outputs(cli, dir, all)?),
        _ => None,
    };
    let (lo, hi) = slice_bounds(cli, &seq, range)?;
    let lo = match skip_existing_start(cli, ospec, named.as_ref(), all, lo, hi) {
        SliceStart::From(n) => n,
        SliceStart::AllExist => {
            eprintln!("fxrun: every output frame exists already (--skip-existing)");
            return Ok(None);
        }
    };
    // Positions of the slice in the sequence, widened by the context frames.
    let first = all.iter().position(|f| f.0 >= lo).unwrap_or(0);
    let last = all
        .iter()
        .rposition(|f| f.0 <= hi)
        .unwrap_or(all.len().saturating_sub(1));
    let from = first.saturating_sub((history + cli.warmup) as usize);
    let to = (last + latency as usize).min(all.len() - 1);
    if effect.graph.has_feedback() && first > 0 && (cli.warmup as usize) < first {
        eprintln!(
            "fxrun: warning: this effect uses feedback (earlier output frames); a slice starting at frame {lo} differs from one whole run unless it warms up over the frames before it (--warmup N)"
        );
    }
    // Frames of one size: checked from the headers before anything is written.
    check_same_size(&all[from..=to])?;
    let load = fxgraph::io::LoadOptions {
        assume_linear: cli.assume_linear,
    };
    Ok(Some(SequenceInput {
        source: Box::new(FilesSource::new(all[from..=to].to_vec(), load)),
        fps,
        y4m_template: None,
        video_in: None,
        hdr_in: None,
        emit: Some((lo, hi)),
        named,
    }))
}

/// The first and last frame numbers of the slice: `--frames` within the sequence, else
/// the whole sequence.
fn slice_bounds(
    cli: &Cli,
    seq: &InputSequence,
    range: Option<FrameRange>,
) -> Result<(u64, u64), Fail> {
    Ok(match range {
        Some(r) => {
            let r = seq.resolve(r).ok_or_else(|| {
                rejected(format!(
                    "--frames {}: no frame of the sequence is in that range",
                    cli.frames.clone().unwrap_or_default()
                ))
            })?;
            (r.start, r.end)
        }
        None => (
            seq.first_number().unwrap_or(0),
            seq.last_number().unwrap_or(0),
        ),
    })
}

/// Where a slice of numbered files starts once --skip-existing has passed over the
/// outputs already written.
enum SliceStart {
    From(u64),
    AllExist,
}

/// With --skip-existing, the first frame in `lo..=hi` whose output is missing (by
/// `named`, else by the output pattern); `lo` without it.
fn skip_existing_start(
    cli: &Cli,
    ospec: &SequenceSpec,
    named: Option<&HashMap<u64, PathBuf>>,
    all: &[(u64, PathBuf)],
    lo: u64,
    hi: u64,
) -> SliceStart {
    if !cli.skip_existing {
        return SliceStart::From(lo);
    }
    let exists: Box<dyn Fn(u64) -> bool + '_> = match named {
        Some(names) => Box::new(move |n| {
            names
                .get(&n)
                .is_some_and(|p| std::fs::symlink_metadata(p).is_ok())
        }),
        None => match output_pattern(cli, ospec) {
            Ok(out) => Box::new(move |n| out.exists(n)),
            Err(_) => return SliceStart::From(lo),
        },
    };
    match all
        .iter()
        .map(|f| f.0)
        .filter(|n| *n >= lo && *n <= hi)
        .find(|n| !exists(*n))
    {
        Some(first_missing) => SliceStart::From(first_missing),
        None => SliceStart::AllExist,
    }
}

/// Sink: numbered files or a y4m or video stream; the output texture format follows.
fn open_sequence_sink(
    cli: &Cli,
    ospec: &SequenceSpec,
    input: &mut SequenceInput,
    effect: &Effect,
) -> Result<(Box<dyn FrameSink>, fxgraph::script::types::Format), Fail> {
    match ospec {
        SequenceSpec::Stdout | SequenceSpec::Y4m(_) | SequenceSpec::Video(_) => {
            let output = stream_output(ospec).expect("a stream spec");
            let plan = StreamPlan {
                template: input.y4m_template.clone(),
                video: input.video_in.as_ref(),
                fps: input.fps,
                emit: input.emit,
                deinterlaces: effect.graph.params.iter().any(|p| p.name == "field_order"),
                display_referred: streams::has_tonemap(cli),
                hdr: input.hdr_in.unwrap_or_default(),
            };
            let opened = open_stream_output(cli, &output, &plan)?;
            Ok((opened.sink, opened.texture_format))
        }
        SequenceSpec::Stdin => Err(rejected("`-` as an output writes stdout; use -o -")),
        SequenceSpec::Dir(dir) if input.named.is_some() => {
            let names = input.named.take().expect("checked");
            std::fs::create_dir_all(dir).map_err(|e| {
                RunError::from(fxgraph::io::IoError::Io {
                    path: dir.clone(),
                    source: e,
                })
            })?;
            let _ = fxgraph::io::sequence::remove_stale_temporaries(dir);
            let probe = names.values().next().cloned().unwrap_or_default();
            files_sink(cli, fxgraph::app::OutputNames::Named(names), &probe)
        }
        spec => {
            let pattern = output_pattern(cli, spec).map_err(RunError::from)?;
            let _ = fxgraph::io::sequence::remove_stale_temporaries(pattern.dir());
            let probe = pattern.path_for(0);
            files_sink(cli, fxgraph::app::OutputNames::Pattern(pattern), &probe)
        }
    }
}

/// An HDR input makes the BT.2390 EETF `tonemap`'s default, with the metadata's
/// peak.
fn apply_hdr_tonemap(cli: &Cli, effect: &mut Effect, hdr: &HdrMetadata) -> Result<(), Fail> {
    let base_set = streams::hdr_tonemap_sets(cli, hdr.peak_nits());
    let effects = streams::video_tonemap(&cli.effects);
    if cli.verbose {
        for s in &base_set[cli.set.len()..] {
            eprintln!("fxrun: note: HDR input: --set {s}");
        }
        if effects != cli.effects {
            eprintln!("fxrun: note: HDR input: tonemap runs as tonemap_video (its measured peak smoothed over frames)");
        }
    }
    if base_set.len() != cli.set.len() || effects != cli.effects {
        *effect = Effect::compile_overrides(&effects, base_set)?;
    }
    Ok(())
}

/// An interlaced y4m input sets the field order of effects that take one.
fn apply_input_field_order(effect: &mut Effect, header: &Y4mHeader) -> Result<(), Fail> {
    use fxgraph::io::y4m::Interlace;
    let order = match header.interlace {
        Interlace::TopFieldFirst => Some("tff"),
        Interlace::BottomFieldFirst => Some("bff"),
        _ => None,
    };
    let has_param = effect.is_effect_param("field_order");
    let user_set = effect.overrides().iter().any(|o| o.name() == "field_order");
    if let (Some(order), true, false) = (order, has_param, user_set) {
        if let Change::Replan(new) = effect.set(None, "field_order", order)? {
            *effect = *new;
        }
    }
    Ok(())
}

/// A sequence's output image files, named by `names`, and the output texture
/// format (from `probe`, one of the names: its extension).
fn files_sink(
    cli: &Cli,
    names: fxgraph::app::OutputNames,
    probe: &std::path::Path,
) -> Result<(Box<dyn FrameSink>, fxgraph::script::types::Format), Fail> {
    let format =
        output_format_for(probe, cli.bit_depth, cli.assume_linear).map_err(RunError::from)?;
    let save = fxgraph::io::SaveOptions {
        bit_depth: cli.bit_depth,
        assume_linear: cli.assume_linear,
    };
    Ok((Box::new(FilesSink { names, save }), format))
}

/// The effect's warnings, each once (each plan, one per image size, may have added
/// the same notes again); its notes (informational: an automatic conversion) with
/// -v only.
pub(crate) fn print_diagnostics(cli: &Cli, effect: &Effect) {
    let mut seen = std::collections::HashSet::new();
    let mut unique = fxgraph::script::Diagnostics::default();
    for d in &effect.warnings.list {
        if seen.insert(d.render(&effect.sources)) {
            unique.push(d.clone());
        }
    }
    let (warnings, notes) = unique.split_notes();
    if !warnings.is_empty() {
        eprint!("{}", warnings.render(&effect.sources));
    }
    if cli.verbose && !notes.is_empty() {
        eprint!("{}", notes.render(&effect.sources));
    }
}

/// The progress bar on stderr (through `indicatif`; nothing when stderr is not a
/// terminal): done/total, rate and ETA; `unit` names what is counted ("frames",
/// "images").
pub(crate) struct ProgressLine {
    bar: Option<indicatif::ProgressBar>,
    unit: &'static str,
}

impl ProgressLine {
    pub(crate) fn new(unit: &'static str) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr())
        });
        ProgressLine { bar, unit }
    }

    /// The callback a sequence or batch run reports to.
    pub(crate) fn callback(&self) -> impl FnMut(Progress) {
        let (bar, unit) = (self.bar.clone(), self.unit);
        let mut styled = false;
        move |p: Progress| {
            let Some(bar) = &bar else {
                return;
            };
            if !styled {
                styled = true;
                let template = match p.total {
                    Some(t) if t > 0 => {
                        bar.set_length(t);
                        format!("[{{bar:30}}] {{pos}}/{{len}} {unit}  {{msg}}  ETA {{eta}}")
                    }
                    _ => format!("{{spinner}} {{pos}} {unit}  {{msg}}"),
                };
                if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
                    bar.set_style(style.progress_chars("#>."));
                }
            }
            let rate = p.done as f64 / p.elapsed.as_secs_f64().max(1e-6);
            let per = if unit == "frames" { " fps" } else { "/s" };
            bar.set_message(format!("{rate:.1}{per}"));
            bar.set_position(p.done);
        }
    }

    /// Leaves the last state on its line.
    pub(crate) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.abandon();
        }
    }
}

/// The numbered files a sequence writes: a pattern, or a folder (`NNNNNN.png`, or the
/// extension `--format` names).
fn output_pattern(cli: &Cli, spec: &SequenceSpec) -> Result<OutputPattern, fxgraph::io::IoError> {
    match (spec, &cli.format) {
        (SequenceSpec::Dir(dir), Some(ext)) => {
            OutputPattern::in_dir(dir, ext.trim_start_matches('.'))
        }
        _ => OutputPattern::new(spec),
    }
}

/// The outputs of a sequence read from files into `-o DIR`: each frame's file stem, with
/// its extension or the one `--format` names (as a batch names them). Refused up front:
/// two frames written to one file, an output replacing an input, and extensions that
/// need different output precisions (a sequence renders one format).
fn named_outputs(
    cli: &Cli,
    dir: &std::path::Path,
    frames: &[(u64, PathBuf)],
) -> Result<HashMap<u64, PathBuf>, Fail> {
    let ext_of = |p: &PathBuf| match &cli.format {
        Some(f) => f.trim_start_matches('.').to_string(),
        None => p.extension().unwrap_or_default().to_string_lossy().into(),
    };
    let items: Vec<BatchItem> = frames
        .iter()
        .map(|(_, p)| BatchItem {
            input: p.clone(),
            output: dir.join(format!(
                "{}.{}",
                p.file_stem().unwrap_or_default().to_string_lossy(),
                ext_of(p)
            )),
        })
        .collect();
    check_outputs(&items)?;
    let mut format = None;
    for it in &items {
        let f = output_format_for(&it.output, cli.bit_depth, cli.assume_linear)
            .map_err(RunError::from)?;
        if format.is_some_and(|first| first != f) {
            return Err(rejected(format!(
                "{}: the frames' file types need different output formats; choose one with --format",
                it.input.display()
            )));
        }
        format = Some(f);
    }
    Ok(frames
        .iter()
        .zip(items)
        .map(|((n, _), it)| (*n, it.output))
        .collect())
}
