//! `fxrun`: apply EFFECT scripts to images (and check, plan and draw them).
//!
//! Exit codes: 0 ok, 1 input rejected (script, shader, image or argument), 2 I/O,
//! GPU or internal error.

use clap::Parser;
use fxgraph::app::{
    apply_to_image_kept, output_format_for, run_sequence, Effect, FilesSink, FilesSource,
    FrameSink, FrameSource, ImageJob, Progress, RunError, SequenceOptions,
};
use fxgraph::gpu::context::{list_adapters, AdapterChoice};
use fxgraph::gpu::executor::Engine;
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions, ReusePolicy};
use fxgraph::graph::{compile, dot, library};
use fxgraph::io::sequence::{parse_frames, InputSequence, OutputPattern, SequenceSpec};
use fxgraph::script::types::format_value;
use std::io::{IsTerminal, Write as _};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// `print!` that checks the write: a closed pipe (`fxrun --list | head -1`) ends the
/// program quietly, any other failure (a full disk) is an I/O error (exit 2).
macro_rules! out {
    ($($arg:tt)*) => {
        stdout_result(std::io::Write::write_fmt(&mut std::io::stdout().lock(), format_args!($($arg)*)))
    };
}

/// `println!` that checks the write (see [`out!`]).
macro_rules! outln {
    ($($arg:tt)*) => {{
        out!($($arg)*);
        out!("\n");
    }};
}

/// Ends the program on a failed write to stdout: quietly with status 0 on a closed
/// pipe, with an error and status 2 otherwise.
fn stdout_result(r: std::io::Result<()>) {
    if let Err(e) = r {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("fxrun: error: stdout: {e}");
        std::process::exit(2);
    }
}

/// An error with its exit code, already reported or to be printed.
struct Fail {
    code: u8,
    message: String,
}

/// What a plan without a real input is made for (`--check`, `--plan`, `--dot`,
/// `--watch`'s shader list): a `w`x`h` 8-bit sRGB image with the renderer's AUX
/// images, and the `--aux NAME=FILE` images as 8-bit sRGB at their own size
/// (the input's where the file's cannot be read: the run reports that).
fn planning_input(cli: &Cli, w: u32, h: u32) -> InputDesc {
    let mut desc = InputDesc::rgba8_srgb(w, h).with_aux(&fxgraph::render::published_aux(true));
    for a in &cli.aux {
        let (name, file) = a.split_once('=').unwrap_or((a, ""));
        desc.aux.retain(|(n, _)| n != name);
        desc.aux
            .push((name.to_string(), fxgraph::script::types::Format::Rgba8Srgb));
        if let Ok(size) = fxgraph::io::image_file_dimensions(Path::new(file)) {
            desc = desc.with_aux_size(name, size);
        }
    }
    desc
}

/// The exit status of a failed run: 1 input rejected; 2 I/O, GPU or internal.
fn exit_code(e: &RunError) -> u8 {
    if e.is_input_error() {
        1
    } else {
        2
    }
}

impl From<RunError> for Fail {
    fn from(e: RunError) -> Self {
        Fail {
            code: exit_code(&e),
            message: e.to_string(),
        }
    }
}

impl From<anyhow::Error> for Fail {
    fn from(e: anyhow::Error) -> Self {
        Fail {
            code: 2,
            message: format!("{e:#}"),
        }
    }
}

fn rejected(message: impl Into<String>) -> Fail {
    Fail {
        code: 1,
        message: message.into(),
    }
}

/// A panic that no library `catch_quiet` caught is a bug of fxrun: one line on
/// stderr (the first one only, if several threads panic) and, from `main`, exit
/// status 2. No backtrace, whatever `RUST_BACKTRACE` says (it is often set for
/// everything on a machine); `FXRUN_BACKTRACE=1` adds one.
fn install_panic_hook() {
    static REPORTED: AtomicBool = AtomicBool::new(false);
    std::panic::set_hook(Box::new(|info| {
        if REPORTED.swap(true, Ordering::SeqCst) {
            return;
        }
        let message = fxgraph::unwind::panic_message(info.payload());
        let place = info
            .location()
            .map(|l| format!(" (at {}:{})", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!("fxrun: internal error (a bug): {message}{place}; please report it");
        if std::env::var_os("FXRUN_BACKTRACE").is_some_and(|v| v != "0") {
            eprintln!("{}", std::backtrace::Backtrace::force_capture());
        }
    }));
}

fn main() -> ExitCode {
    startup::mark_main();
    install_panic_hook();
    match std::panic::catch_unwind(real_main) {
        Ok(code) => code,
        // Reported by the hook.
        Err(_) => ExitCode::from(2),
    }
}

fn real_main() -> ExitCode {
    if std::env::var_os("FXRUN_TEST_INTERNAL_PANIC").is_some() {
        // How tests reach the panic hook: there is no known panic to trigger.
        panic!("FXRUN_TEST_INTERNAL_PANIC is set");
    }
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // Silences a harmless warning of the Vulkan loader on headless machines.
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => 0,
                _ => 1,
            };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    logging::init(cli.verbose);
    let result = run(cli);
    stdout_result(std::io::stdout().flush());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            print_fail(&f);
            ExitCode::from(f.code)
        }
    }
}

/// Prints a failure's message (diagnostics already rendered are printed as they are).
fn print_fail(f: &Fail) {
    if !f.message.is_empty() {
        let msg = f.message.trim_end();
        if msg.contains(": error:") || msg.starts_with("error") {
            eprintln!("{msg}");
        } else {
            eprintln!("fxrun: error: {msg}");
        }
    }
}

/// The Ctrl-C flag of sequences, batches and `--watch`: one handler for the process
/// (the `ctrlc` crate takes one), installed on first use.
fn stop_flag() -> Arc<AtomicBool> {
    static STOP: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    STOP.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
        stop
    })
    .clone()
}

fn parse_size(s: &str) -> Result<(u32, u32), Fail> {
    let bad = || rejected(format!("--size {s}: expected WIDTHxHEIGHT, e.g. 1920x1080"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

fn adapter_choice(a: &Option<String>) -> AdapterChoice {
    match a {
        None => AdapterChoice::Auto,
        Some(s) => match s.parse::<usize>() {
            Ok(i) => AdapterChoice::Index(i),
            Err(_) => AdapterChoice::NameContains(s.clone()),
        },
    }
}

fn run(mut cli: Cli) -> Result<(), Fail> {
    startup::mark_job();
    #[cfg(feature = "slang")]
    add_preset_luts(&mut cli)?;
    let execution: fxgraph::gpu::executor::Execution = cli
        .execution
        .parse()
        .map_err(|e: String| rejected(format!("--execution: {e}")))?;
    fxgraph::gpu::executor::set_default_execution(execution);
    if cli.adapters {
        return print_adapters();
    }
    if cli.list {
        print_effect_list();
        return Ok(());
    }
    if cli.view {
        return run_view(&cli);
    }
    if cli.view_frames.is_some() || !cli.view_do.is_empty() || cli.screenshot.is_some() {
        return Err(rejected(
            "--view-frames, --view-do and --screenshot are options of --view",
        ));
    }
    if cli.watch {
        return watch::run_watch(&cli);
    }
    // The renderer as the input: `--scene`, or `-o OUT` alone (the built-in scene
    // through the default chain).
    let default_render = cli.effects.is_empty() && cli.input.is_empty() && cli.output.is_some();
    if cli.scene.is_some() || default_render {
        return run_scene_cli(&cli);
    }
    if cli.effects.is_empty() {
        return Err(no_effect_error(&cli));
    }
    if cli.check || cli.dot.is_some() || cli.plan || cli.describe {
        return run_analysis(&cli);
    }
    let mut kept = None;
    let result = run_job(&cli, &mut kept);
    skip_teardown(kept);
    result
}

/// `--adapters`: the GPU adapters, one a line.
fn print_adapters() -> Result<(), Fail> {
    let list = list_adapters();
    if list.is_empty() {
        return Err(Fail {
            code: 2,
            message: "no GPU adapter found (install mesa-vulkan-drivers for lavapipe)".into(),
        });
    }
    for a in list {
        outln!("{a}");
    }
    Ok(())
}

/// `--list`: the built-in effects with their descriptions and the pass parameters
/// `--set PASS.NAME=VALUE` takes.
fn print_effect_list() {
    for (name, desc) in library::builtin_effects() {
        outln!("{name:<20} {desc}");
        // The pass parameters `--set PASS.NAME=VALUE` takes, by name.
        let req = fxgraph::lookup::DiskEffects::request(std::slice::from_ref(&name), &[]);
        if let (Some(graph), _, _) = compile(&req) {
            // Those the effect sets (mostly from its parameters) by count.
            let (bound, free): (Vec<_>, Vec<_>) = pass_param_rows(&graph)
                .into_iter()
                .partition(|(_, p)| p.set.is_some());
            let free: Vec<String> = free.into_iter().map(|(key, _)| key).collect();
            let line = match (free.is_empty(), bound.len()) {
                (true, 0) => continue,
                (false, 0) => free.join(" "),
                (false, n) => format!("{} (and {n} set by the effect)", free.join(" ")),
                (true, n) => format!("{n}, set by the effect (see --describe)"),
            };
            outln!("{:<20}   pass parameters: {line}", "");
        }
    }
}

/// Why a run without an effect is refused: an input that looks like an effect given
/// after `-i`, or no effect at all.
fn no_effect_error(cli: &Cli) -> Fail {
    if let Some(e) = cli.input.iter().find(|i| batch::effect_after_input(i)) {
        return rejected(format!(
            "no effect given: `{}` was read as an input; effects go before -i (fxrun EFFECT... -i INPUT... -o OUTPUT)",
            e.display()
        ));
    }
    rejected("no effect given (try `fxrun --list`, or `fxrun --help`)")
}

/// An error already printed (exit 1).
fn reported() -> Fail {
    Fail {
        code: 1,
        message: String::new(),
    }
}

/// `--check`, `--dot`, `--plan`, `--describe`: the effect compiled and planned without
/// a GPU, and what was asked for printed.
fn run_analysis(cli: &Cli) -> Result<(), Fail> {
    let req = fxgraph::lookup::DiskEffects::request_with(&cli.effects, cli.set.clone());
    let (graph, diags, mut sources) = fxgraph::shader::compile_all(&req);
    if !diags.is_empty() {
        eprint!("{}", diags.render(&sources));
    }
    let Some(graph) = graph else {
        return Err(reported());
    };
    if cli.describe {
        describe(&graph);
        // Describing needs no input: an effect reading an `--aux` image
        // (chroma_composite's AUX.background) is described without one.
        if !cli.check && !cli.plan && cli.dot.is_none() {
            return Ok(());
        }
    }
    let p = checked_plan(cli, &graph, &mut sources)?;
    if let Some(target) = &cli.dot {
        write_dot(&graph, &p, target)?;
    }
    if cli.plan {
        if cli.json {
            outln!(
                "{}",
                serde_json::to_string_pretty(&p.to_json()).expect("plan serializes")
            );
        } else {
            out!("{}", p.render());
        }
    }
    Ok(())
}

/// The plan of `graph` for the planning input (`--size`, `--policy`); with `--check`
/// its shaders are loaded and checked against the script too (no GPU needed). Its
/// notes are printed; errors among them refuse it.
fn checked_plan(
    cli: &Cli,
    graph: &fxgraph::graph::Graph,
    sources: &mut fxgraph::script::SourceMap,
) -> Result<fxgraph::graph::plan::Plan, Fail> {
    let (w, h) = match &cli.size {
        Some(s) => parse_size(s)?,
        None => (1920, 1080),
    };
    let desc = planning_input(cli, w, h);
    let policy = match cli.policy.as_str() {
        "min-peak" => ReusePolicy::MinPeak,
        "pool" => ReusePolicy::Pool,
        other => {
            return Err(rejected(format!(
                "--policy {other}: expected min-peak or pool"
            )))
        }
    };
    let planned = plan(
        graph,
        &desc,
        &PlanOptions {
            policy,
            output_format: None,
        },
    );
    let (p, mut notes) = match planned {
        Ok(x) => x,
        Err(d) => {
            eprint!("{}", d.render(sources));
            return Err(reported());
        }
    };
    // Shaders are found, preprocessed, reflected and checked against the
    // script too (no GPU needed).
    // (--plan and --dot show the graph whatever its shaders say.)
    if cli.check {
        let (_, shader_diags) = fxgraph::shader::load_plan_shaders(graph, &p, sources, &[]);
        notes.extend(shader_diags);
    }
    notes.sort();
    if !notes.is_empty() && (!cli.json || notes.has_errors()) {
        eprint!("{}", notes.render(sources));
    }
    if notes.has_errors() {
        return Err(reported());
    }
    Ok(p)
}

/// `--dot TARGET`: the graph with its plan in Graphviz form, to stdout (`-`) or a file.
fn write_dot(
    graph: &fxgraph::graph::Graph,
    p: &fxgraph::graph::plan::Plan,
    target: &str,
) -> Result<(), Fail> {
    let text = dot::to_dot(graph, Some(p));
    if target == "-" {
        out!("{text}");
    } else {
        fxgraph::io::write_atomic(std::path::Path::new(target), |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| fxgraph::io::IoError::Io {
                    path: target.into(),
                    source: e,
                })
        })
        .map_err(RunError::from)?;
    }
    Ok(())
}

/// Lowers the slang presets among the effects (so a preset that cannot run is
/// reported before anything else) and adds their LUT textures to the auxiliary
/// images, unless `--aux` gives one of the same name.
#[cfg(feature = "slang")]
fn add_preset_luts(cli: &mut Cli) -> Result<(), Fail> {
    for e in cli.effects.clone() {
        if !fxgraph::slang::is_preset(&e) {
            continue;
        }
        let lowered =
            fxgraph::slang::lower_preset(std::path::Path::new(&e)).map_err(|err| Fail {
                code: if matches!(err, fxgraph::slang::SlangError::Cache { .. }) {
                    2
                } else {
                    1
                },
                message: err.to_string(),
            })?;
        for (name, path) in lowered.luts {
            let given = cli
                .aux
                .iter()
                .any(|a| a.split_once('=').map(|(n, _)| n) == Some(name.as_str()));
            if !given {
                cli.aux.push(format!("{name}={}", path.display()));
            }
        }
    }
    Ok(())
}

/// The auxiliary images of `--aux NAME=FILE`.
pub(crate) fn aux_images(cli: &Cli) -> Result<Vec<(String, PathBuf)>, Fail> {
    cli.aux
        .iter()
        .map(|a| {
            let (n, f) = a
                .split_once('=')
                .filter(|(n, f)| !n.trim().is_empty() && !f.is_empty())
                .ok_or_else(|| rejected(format!("--aux {a}: expected NAME=FILE")))?;
            Ok((n.to_string(), PathBuf::from(f)))
        })
        .collect()
}

/// `--size WxH` with `-i INPUT`: the viewport, the output size that passes scale
/// from as `OUT.RELATIVE_TO = VIEWPORT` (a slang preset's viewport and its last
/// pass). The run refuses it when no pass of the effects reads it
/// (`app::run_frames`, with the effect it compiles anyway).
pub(crate) fn viewport_of(cli: &Cli) -> Result<Option<(u32, u32)>, Fail> {
    cli.size.as_deref().map(parse_size).transpose()
}

/// An image, batch or sequence run (what `--watch` re-runs). The device it creates
/// is left in `kept` (one it holds is used).
fn run_job(cli: &Cli, kept: &mut Option<Engine>) -> Result<(), Fail> {
    if try_run_batch(cli, kept)? {
        return Ok(());
    }
    if let ([i], Some(o)) = (cli.input.as_slice(), &cli.output) {
        let (ispec, ospec) = (
            SequenceSpec::parse_input(&i.to_string_lossy()),
            SequenceSpec::parse_output(&o.to_string_lossy()),
        );
        if ispec.is_sequence() || ispec.is_stream() || ospec.is_sequence() || ospec.is_stream() {
            // Frames from files into a name without an image extension: a folder.
            let ospec = match ospec {
                SequenceSpec::Single(p)
                    if ispec.is_sequence() && !ispec.is_stream() && p.extension().is_none() =>
                {
                    SequenceSpec::Dir(p)
                }
                other => other,
            };
            return run_sequence_cli(cli, ispec, ospec, kept);
        }
    }
    let ([input], Some(output)) = (cli.input.as_slice(), cli.output.clone()) else {
        return Err(rejected("give an input and an output image: -i INPUT -o OUTPUT (or --check, --plan, --dot, --describe)"));
    };
    let input = input.clone();
    streams::check_color_options(cli, false, false)?;
    if cli.format.is_some() {
        return Err(rejected(
            "--format sets the format of -o DIR outputs; an output file has its own extension",
        ));
    }
    let aux = aux_images(cli)?;
    let viewport = viewport_of(cli)?;
    let job = ImageJob {
        effects: cli.effects.clone(),
        overrides: cli.set.clone(),
        input,
        output,
        bit_depth: cli.bit_depth,
        assume_linear: cli.assume_linear,
        aux,
        timings: cli.timings || cli.timings_json.is_some(),
        viewport,
    };
    let report = apply_to_image_kept(&job, kept, &adapter_choice(&cli.adapter))?;
    finish_report(cli, &report)?;
    Ok(())
}

#[path = "fxrun/args.rs"]
mod args;
#[path = "fxrun/batch.rs"]
mod batch;
#[path = "fxrun/describe.rs"]
mod describe;
#[path = "fxrun/logging.rs"]
mod logging;
#[path = "fxrun/report.rs"]
mod report;
#[path = "fxrun/scene.rs"]
mod scene;
#[path = "fxrun/sequence.rs"]
mod sequence;
#[path = "fxrun/startup.rs"]
mod startup;
#[path = "fxrun/streams.rs"]
mod streams;
#[path = "fxrun/teardown.rs"]
mod teardown;
#[path = "fxrun/watch.rs"]
mod watch;

#[cfg(feature = "view")]
#[path = "fxrun/view/mod.rs"]
mod view;

/// `--view`: the viewer window.
#[cfg(feature = "view")]
fn run_view(cli: &Cli) -> Result<(), Fail> {
    view::run_view(cli)
}

/// `--view` in a build without the `view` feature.
#[cfg(not(feature = "view"))]
fn run_view(_cli: &Cli) -> Result<(), Fail> {
    Err(rejected(
        "--view: this fxrun was built without the viewer (cargo feature `view`)",
    ))
}

use args::Cli;
use batch::{check_outputs, check_same_size, collect_inputs, try_run_batch};
use describe::{describe, pass_param_rows};
use report::finish_report;
use scene::run_scene_cli;
use sequence::{print_diagnostics, run_sequence_cli, ProgressLine};
use teardown::skip_teardown;
