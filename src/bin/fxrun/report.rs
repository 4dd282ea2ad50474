//! `fxrun`: the one printer of a job's [`RunReport`] (an image, a batch, a sequence, a
//! scene): failures always, each output with `-v`, a batch's summary line, and with
//! `--timings` where the time went. Timings go to stdout for an image or a scene (the
//! output is a file) and to stderr for batches and sequences (stdout may be a y4m
//! stream).

use super::*;
use fxgraph::app::report::SceneStats;
use fxgraph::app::{JobKind, RunReport};
use fxgraph::gpu::executor::PassTiming;

/// Print what `fxrun` reports about a finished job and write it to
/// `--timings-json` when that is given; both add where the whole process's time
/// went (`process`: [`super::startup`]).
pub(crate) fn finish_report(cli: &Cli, report: &RunReport) -> Result<(), Fail> {
    let process = super::startup::times(report.wall_ms);
    print_report(cli, report);
    if cli.timings {
        if let Some(p) = &process {
            print_timing_line(report, &super::startup::line(p));
        }
    }
    match &cli.timings_json {
        Some(path) => write_json(path, report, process),
        None => Ok(()),
    }
}

/// The `--timings-json` file: the report's keys, in their order, then `process`.
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    #[serde(flatten)]
    report: &'a RunReport,
    #[serde(skip_serializing_if = "Option::is_none")]
    process: Option<super::startup::ProcessTimes>,
}

/// Write the report as pretty JSON to `path`, atomically (`--timings-json`), with
/// the process's times as `process`.
fn write_json(
    path: &std::path::Path,
    report: &RunReport,
    process: Option<super::startup::ProcessTimes>,
) -> Result<(), Fail> {
    let text = serde_json::to_string_pretty(&JsonReport { report, process }).map_err(|e| Fail {
        code: 2,
        message: e.to_string(),
    })?;
    fxgraph::io::write_atomic(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| fxgraph::io::IoError::Io {
                path: path.to_path_buf(),
                source: e,
            })
    })
    .map_err(RunError::from)?;
    Ok(())
}

/// Print what `fxrun` reports about a finished job.
fn print_report(cli: &Cli, r: &RunReport) {
    for f in &r.failed {
        if f.message.contains(&f.input) {
            eprintln!("fxrun: error: {}", f.message);
        } else {
            eprintln!("fxrun: error: {}: {}", f.input, f.message);
        }
    }
    if !r.warnings.is_empty() {
        eprint!("{}", r.warnings);
    }
    // Notes (an automatic conversion) are informational: shown with -v only.
    if cli.verbose && !r.notes.is_empty() {
        eprint!("{}", r.notes);
    }
    if cli.verbose {
        for d in &r.done {
            eprintln!(
                "fxrun: {} -> {} ({}x{}, {:.1} ms)",
                d.input,
                d.output,
                d.width,
                d.height,
                d.total_ms()
            );
        }
    }
    if r.job == JobKind::Batch {
        print_batch_summary(r);
    }
    if cli.timings {
        for line in timing_lines(r) {
            print_timing_line(r, &line);
        }
    }
}

/// A `--timings` line: on stdout for an image or a scene, else on stderr.
fn print_timing_line(r: &RunReport, line: &str) {
    if matches!(r.job, JobKind::Image | JobKind::Scene) {
        outln!("{line}");
    } else {
        eprintln!("{line}");
    }
}

fn print_batch_summary(r: &RunReport) {
    let plural = |n: u64| if n == 1 { "image" } else { "images" };
    let done = r.done.len() as u64;
    eprintln!(
        "fxrun: {} {} in {:.2} s, {:.1} ms per image (median), {} plan{} ({})",
        done,
        plural(done),
        r.wall_ms / 1e3,
        r.median_ms(),
        r.plans,
        if r.plans == 1 { "" } else { "s" },
        r.adapter
    );
    if !r.failed.is_empty() {
        let stopped = match r.not_run() {
            0 => String::new(),
            n => {
                format!("; stopped at the first failure, {n} not run (--keep-going runs the rest)")
            }
        };
        let total = r.frames_total.unwrap_or(0);
        eprintln!(
            "fxrun: {} of {} {} failed{stopped}",
            r.failed.len(),
            total,
            plural(total)
        );
    }
}

/// The `--timings` lines of a report.
fn timing_lines(r: &RunReport) -> Vec<String> {
    let size = r
        .done
        .last()
        .map(|d| format!("{}x{}", d.width, d.height))
        .unwrap_or_else(|| "-".into());
    let mut out = match &r.scene {
        Some(s) => scene_header_lines(r, s, &size),
        None => vec![job_header_line(r, &size)],
    };
    out.extend(pass_lines(&r.passes));
    out.push(stage_line(r));
    if r.plans > 0 {
        let mib = |b: u64| b as f64 / 1048576.0;
        out.push(format!(
            "transient textures: peak {:.2} MiB (lower bound {:.2}, naive {:.2})",
            mib(r.memory.peak_bytes),
            mib(r.memory.lower_bound_bytes),
            mib(r.memory.naive_bytes)
        ));
    }
    out
}

/// A rendered scene's first lines: the adapter, the scene and its lights, the render
/// passes' GPU times, the renderer's CPU time by step, the shadows.
fn scene_header_lines(r: &RunReport, s: &SceneStats, size: &str) -> Vec<String> {
    let mut out = Vec::new();
    out.push(format!(
        "adapter: {} ({})  scene {} ({} triangles, {} lights visible, {} culling: {} light-cluster entries, {:.1} KiB)  {size}",
        r.adapter,
        r.backend,
        s.scene,
        s.triangles,
        s.lights_visible,
        s.light_culling,
        s.cluster_entries,
        s.cluster_bytes as f64 / 1024.0,
    ));
    for (name, ms) in &s.render_passes {
        out.push(format!("  render {name:<26} gpu {ms:>8.2} ms"));
    }
    if !s.render_cpu_split.is_empty() {
        let parts: Vec<String> = s
            .render_cpu_split
            .iter()
            .map(|(name, ms)| format!("{name} {ms:.2}"))
            .collect();
        out.push(format!(
            "  render cpu {:.2} ms: {} ms; pipelines created on first use {:.2} ms",
            s.render_cpu_ms,
            parts.join(", "),
            s.render_pipelines_ms
        ));
    }
    out.push(format!(
        "  shadows {}: {} layers ({} rendered over the run, the others kept), {:.1} MiB of shadow maps",
        s.shadows,
        s.shadow_layers,
        s.shadow_layers_rendered,
        s.shadow_map_bytes as f64 / (1u64 << 20) as f64
    ));
    out
}

/// An image's or a sequence's first line: the adapter, the image size or the frames.
fn job_header_line(r: &RunReport, size: &str) -> String {
    match r.job {
        JobKind::Image => format!("adapter: {} ({})  image {size}", r.adapter, r.backend),
        _ => format!(
            "adapter: {} ({})  frames: {} in, {} out  wall {:.1} ms  {:.2} fps  ({} plan{})",
            r.adapter,
            r.backend,
            r.frames_in,
            r.done.len(),
            r.wall_ms,
            r.fps(),
            r.plans,
            if r.plans == 1 { "" } else { "s" }
        ),
    }
}

/// Where the time went: by step (a scene, an image) or by stage (a sequence or batch).
fn stage_line(r: &RunReport) -> String {
    let st = &r.stages;
    match (&r.scene, r.job) {
        (Some(s), _) => format!(
            "load {:.1} ms | render cpu {:.1} gpu {} | pipelines {:.1} | effects {:.1} | readback {:.1} | encode {:.1} | total {:.1} ms",
            s.load_ms,
            s.render_cpu_ms,
            s.render_gpu_ms
                .map(|g| format!("{g:.1}"))
                .unwrap_or_else(|| "-".into()),
            r.steps.pipeline_ms,
            r.steps.passes_ms,
            r.steps.readback_ms,
            st.encode_busy_ms,
            r.wall_ms
        ),
        (None, JobKind::Image) => format!(
            "compile {:.1} ms | decode {:.1} | device {:.1} (created in {:.1}, overlapping the decode) | pipelines {:.1} | upload {:.1} | passes {:.1} | readback {:.1} | encode {:.1} | total {:.1} ms",
            r.compile_ms,
            st.decode_busy_ms,
            r.device_wait_ms,
            r.device_created_ms,
            r.steps.pipeline_ms,
            r.steps.upload_ms,
            r.steps.passes_ms,
            r.steps.readback_ms,
            st.encode_busy_ms,
            r.wall_ms
        ),
        (None, _) => {
            let (d, g, e) = r.utilisation();
            format!(
                "stage busy: decode {:.0} ms ({:.0}%), gpu {:.0} ms ({:.0}%), encode {:.0} ms ({:.0}%); the encoder waited {:.0} ms for the GPU; wall {:.0} ms  (frames held at most: {})",
                st.decode_busy_ms,
                d * 100.0,
                st.gpu_busy_ms,
                g * 100.0,
                st.encode_busy_ms,
                e * 100.0,
                st.readback_wait_ms,
                r.wall_ms,
                r.frames_held_max
            )
        }
    }
}

/// The passes with their GPU (and CPU recording) time and the path they ran on,
/// one line each; over a sequence, the medians of its frames.
fn pass_lines(passes: &[PassTiming]) -> Vec<String> {
    if passes.is_empty() {
        return Vec::new();
    }
    let frames = passes.iter().map(|p| p.frames).max().unwrap_or(1);
    let mut out = vec![format!(
        "  {:<32} {:>11} {:<10} {:<8} {:>9} {:>9}{}",
        "pass",
        "size",
        "format",
        "runs as",
        "gpu ms",
        "cpu ms",
        if frames > 1 {
            format!("  (medians of {frames} frames)")
        } else {
            String::new()
        }
    )];
    for p in passes {
        let gpu = p
            .gpu_ms
            .map(|g| format!("{g:.3}"))
            .unwrap_or_else(|| "-".into());
        out.push(format!(
            "  {:<32} {:>11} {:<10} {:<8} {:>9} {:>9.2}",
            p.path,
            format!("{}x{}", p.width, p.height),
            p.format,
            p.execution.name(),
            gpu,
            p.cpu_ms
        ));
    }
    out
}
