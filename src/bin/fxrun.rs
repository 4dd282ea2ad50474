//! `fxrun`: apply EFFECT scripts to images (and check, plan and draw them).
//!
//! Exit codes: 0 ok, 1 input rejected (script, shader, image or argument), 2 I/O,
//! GPU or internal error.

use clap::Parser;
use fxgraph::gpu::context::{list_adapters, AdapterChoice};
use fxgraph::gpu::executor::Engine;
use fxgraph::gpu::runner::{apply_to_image, ImageJob, JobReport, RunError};
use fxgraph::gpu::runner::{output_format_for, Effect};
use fxgraph::gpu::sequence::{
    run_sequence, FilesSink, FilesSource, FrameSink, FrameSource, Progress, SequenceOptions,
    Y4mSink, Y4mSource,
};
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions, ReusePolicy};
use fxgraph::graph::{compile, dot, library, CompileRequest, Override};
use fxgraph::io::sequence::{parse_frames, InputSequence, OutputPattern, SequenceSpec};
use fxgraph::script::types::format_value;
use std::io::{IsTerminal, Write as _};
use std::path::PathBuf;
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

/// Largest `--queue`: frames held between the stages.
const MAX_QUEUE: u64 = 64;
/// Largest `--lights`: random point lights added to a scene.
const MAX_LIGHTS: u64 = 100_000;
/// Largest `--warmup`: frames run before the first written one.
const MAX_WARMUP: u64 = 1_000_000;

#[derive(Parser, Debug)]
#[command(
    name = "fxrun",
    version,
    about = "Apply declarative filter-graph effects (EFFECT scripts) to images on the GPU",
    after_help = "EFFECT is a path to an .fx file or a built-in effect name (see --list).\n\
Examples:\n  fxrun glow -i photo.png -o glow.png\n  fxrun gaussian_blur --set sigma=8 -i in.png -o out.png --timings\n  fxrun effects/glow.fx --check\n  fxrun glow --plan --size 1920x1080 --json\n\n\
Exit codes: 0 ok, 1 input rejected, 2 I/O, GPU or internal error."
)]
struct Cli {
    /// Effects to apply in order (paths to .fx files or built-in names).
    effects: Vec<String>,
    /// Input image.
    #[arg(short, long)]
    input: Option<PathBuf>,
    /// Output image (format from the extension).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Set a parameter: NAME=VALUE (effect), EFFECT.NAME=VALUE, or PASS.NAME=VALUE.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// An auxiliary input image: NAME=FILE (read by AUX.NAME).
    #[arg(long = "aux", value_name = "NAME=FILE")]
    aux: Vec<String>,
    /// Bits per channel of the output file (8, 16, 32 where the format allows).
    #[arg(long)]
    bit_depth: Option<u8>,
    /// Treat 8/16-bit files as linear data (no sRGB decode on load or encode on save).
    #[arg(long)]
    assume_linear: bool,
    /// Print one row per pass and the run's time split.
    #[arg(long)]
    timings: bool,
    /// Write the timings as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    timings_json: Option<PathBuf>,
    /// Only check the effect: print diagnostics, exit 0 (warnings allowed) or 1.
    #[arg(long)]
    check: bool,
    /// Write the graph as Graphviz DOT to FILE (`-` for stdout).
    #[arg(long, value_name = "FILE", value_parser = clap::builder::NonEmptyStringValueParser::new())]
    dot: Option<String>,
    /// Print the schedule, the texture lifetime steps and the memory figures.
    #[arg(long)]
    plan: bool,
    /// Input size for --plan/--dot/--check: WxH.
    #[arg(long, value_name = "WxH")]
    size: Option<String>,
    /// With --plan: one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Texture reuse policy for --plan: min-peak (default) or pool.
    #[arg(long, default_value = "min-peak")]
    policy: String,
    /// List the built-in effects.
    #[arg(long)]
    list: bool,
    /// List the effect's passes and parameters.
    #[arg(long)]
    describe: bool,
    /// List the GPU adapters.
    #[arg(long)]
    adapters: bool,
    /// Pick an adapter by index (see --adapters) or by part of its name.
    #[arg(long)]
    adapter: Option<String>,
    /// Sequences: only write the outputs of input frames A to B (inclusive);
    /// history/future frames outside the range are still read.
    #[arg(long, value_name = "A..B")]
    frames: Option<String>,
    /// Sequences: frames per second (the `time` shaders see; y4m input sets it).
    #[arg(long)]
    fps: Option<f64>,
    /// Sequences: outputs per input frame (2 for field-rate deinterlacing).
    #[arg(long, default_value_t = 1)]
    rate: u32,
    /// Sequences: frames before --frames to run without writing, so feedback
    /// effects warm up (at most 1000000).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_WARMUP))]
    warmup: u64,
    /// Sequences: skip frames whose output file exists (resume an interrupted run).
    #[arg(long)]
    skip_existing: bool,
    /// Sequences: frames queued between decode, GPU and encode (1 to 64).
    #[arg(long, default_value_t = 3,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_QUEUE))]
    queue: usize,
    /// Render a scene with the deferred renderer as the effect input:
    /// builtin:room, builtin:bench, or a .gltf/.glb file (size from --size).
    #[arg(long, value_parser = clap::builder::NonEmptyStringValueParser::new())]
    scene: Option<String>,
    /// Scene camera: a glTF camera index or name, or eye=x,y,z;target=x,y,z;fov=deg.
    #[arg(long)]
    camera: Option<String>,
    /// Scene: add N random point lights (at most 100000).
    #[arg(long, default_value_t = 0,
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=MAX_LIGHTS))]
    lights: usize,
    /// Scene: seed of the random lights.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Scene: deferred (default), light-prepass or forward.
    #[arg(long, default_value = "deferred")]
    renderer: String,
    /// Scene: write every G-buffer image into DIR.
    #[arg(long, value_name = "DIR")]
    gbuffer: Option<PathBuf>,
    /// Scene: a file of MATERIAL definitions; a definition named like a scene
    /// material replaces it (docs/materials.md).
    #[arg(long, value_name = "FILE")]
    materials: Option<PathBuf>,
    /// Scene: SCENE_MATERIAL=DEFINITION: use a definition of --materials for a scene
    /// material (`*` for all of them). Repeatable.
    #[arg(long = "material", value_name = "NAME=DEF")]
    material: Vec<String>,
    /// Scene: how material features select code: preprocess (#ifdef variants,
    /// default), override (pipeline constants) or branch (run-time branches).
    #[arg(long, default_value = "preprocess")]
    variants: String,
    /// Scene: list each material (surface and lighting shader, variant features)
    /// and the pipelines compiled.
    #[arg(long)]
    describe_materials: bool,
    /// Scene: add ambient light of this radiance (V or R,G,B, linear); a scene
    /// otherwise renders only the lights it has.
    #[arg(long, value_name = "RGB")]
    ambient: Option<String>,
}

/// An error with its exit code, already reported or to be printed.
struct Fail {
    code: u8,
    message: String,
}

impl From<RunError> for Fail {
    fn from(e: RunError) -> Self {
        Fail {
            code: e.exit_code() as u8,
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

fn main() -> ExitCode {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,wgpu_hal::gles::egl=off"),
    )
    .init();
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
    let result = run(cli);
    stdout_result(std::io::stdout().flush());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            if !f.message.is_empty() {
                let msg = f.message.trim_end();
                if msg.contains(": error:") || msg.starts_with("error") {
                    eprintln!("{msg}");
                } else {
                    eprintln!("fxrun: error: {msg}");
                }
            }
            ExitCode::from(f.code)
        }
    }
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

fn run(cli: Cli) -> Result<(), Fail> {
    if cli.adapters {
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
        return Ok(());
    }
    if cli.list {
        for (name, desc) in library::builtin_effects() {
            outln!("{name:<20} {desc}");
            // The pass parameters `--set PASS.NAME=VALUE` takes, by name.
            let req = CompileRequest {
                effects: vec![name.clone()],
                ..Default::default()
            };
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
        return Ok(());
    }
    // The renderer as the input: `--scene`, or `-o OUT` alone (the built-in scene
    // through the default chain).
    let default_render = cli.effects.is_empty() && cli.input.is_none() && cli.output.is_some();
    if cli.scene.is_some() || default_render {
        return run_scene_cli(&cli);
    }
    if cli.effects.is_empty() {
        return Err(rejected(
            "no effect given (try `fxrun --list`, or `fxrun --help`)",
        ));
    }
    let req = CompileRequest {
        effects: cli.effects.clone(),
        overrides: cli
            .set
            .iter()
            .map(|a| Override { arg: a.clone() })
            .collect(),
        search_dirs: Vec::new(),
    };
    let analysis = cli.check || cli.dot.is_some() || cli.plan || cli.describe;
    if analysis {
        let (graph, diags, mut sources) = compile(&req);
        if !diags.is_empty() {
            eprint!("{}", diags.render(&sources));
        }
        let Some(graph) = graph else {
            return Err(Fail {
                code: 1,
                message: String::new(),
            });
        };
        if cli.describe {
            describe(&graph);
            // Describing needs no input: an effect reading an `--aux` image
            // (chroma_composite's AUX.background) is described without one.
            if !cli.check && !cli.plan && cli.dot.is_none() {
                return Ok(());
            }
        }
        let (w, h) = match &cli.size {
            Some(s) => parse_size(s)?,
            None => (1920, 1080),
        };
        let mut desc =
            InputDesc::rgba8_srgb(w, h).with_aux(&fxgraph::deferred::published_aux(true));
        // `--aux NAME=FILE` images are 8-bit sRGB for planning purposes.
        for a in &cli.aux {
            let name = a.split_once('=').map(|(n, _)| n).unwrap_or(a);
            desc.aux.retain(|(n, _)| n != name);
            desc.aux
                .push((name.to_string(), fxgraph::script::types::Format::Rgba8Srgb));
        }
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
            &graph,
            &desc,
            &PlanOptions {
                policy,
                output_format: None,
            },
        );
        let (p, notes) = match planned {
            Ok(x) => x,
            Err(d) => {
                eprint!("{}", d.render(&sources));
                return Err(Fail {
                    code: 1,
                    message: String::new(),
                });
            }
        };
        // Shaders are found, preprocessed, reflected and checked against the
        // script too (no GPU needed).
        // (--plan and --dot show the graph whatever its shaders say.)
        let mut notes = notes;
        if cli.check {
            let (_, shader_diags) =
                fxgraph::shader::load_plan_shaders(&graph, &p, &mut sources, &[]);
            notes.extend(shader_diags);
        }
        notes.sort();
        if !notes.is_empty() && (!cli.json || notes.has_errors()) {
            eprint!("{}", notes.render(&sources));
        }
        if notes.has_errors() {
            return Err(Fail {
                code: 1,
                message: String::new(),
            });
        }
        if let Some(target) = &cli.dot {
            let text = dot::to_dot(&graph, Some(&p));
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
        return Ok(());
    }
    if let (Some(i), Some(o)) = (&cli.input, &cli.output) {
        let (ispec, ospec) = (
            SequenceSpec::parse_input(&i.to_string_lossy()),
            SequenceSpec::parse_output(&o.to_string_lossy()),
        );
        if ispec.is_sequence() || ispec.is_stream() || ospec.is_sequence() || ospec.is_stream() {
            return run_sequence_cli(&cli, ispec, ospec);
        }
    }
    let (Some(input), Some(output)) = (cli.input.clone(), cli.output.clone()) else {
        return Err(rejected("give an input and an output image: -i INPUT -o OUTPUT (or --check, --plan, --dot, --describe)"));
    };
    let mut aux = Vec::new();
    for a in &cli.aux {
        let (n, f) = a
            .split_once('=')
            .filter(|(n, f)| !n.trim().is_empty() && !f.is_empty())
            .ok_or_else(|| rejected(format!("--aux {a}: expected NAME=FILE")))?;
        aux.push((n.to_string(), PathBuf::from(f)));
    }
    let job = ImageJob {
        effects: cli.effects.clone(),
        overrides: cli.set.clone(),
        input,
        output,
        bit_depth: cli.bit_depth,
        assume_linear: cli.assume_linear,
        aux,
        timings: cli.timings || cli.timings_json.is_some(),
    };
    let report = apply_to_image(&job, None, &adapter_choice(&cli.adapter))?;
    if !report.warnings.is_empty() {
        eprint!("{}", report.warnings);
    }
    if cli.timings {
        print_timings(&report);
    }
    if let Some(path) = &cli.timings_json {
        write_json(path, &report)?;
    }
    Ok(())
}

/// The settable pass parameters of `graph` with the `--set` key of each:
/// `PASS.NAME`, or `EFFECT/PASS.NAME` where passes of two effects share a name.
fn pass_param_rows(graph: &fxgraph::graph::Graph) -> Vec<(String, fxgraph::shader::PassParamInfo)> {
    let infos = fxgraph::shader::pass_parameters(graph, &[]);
    let shared = |short: &str| {
        graph
            .schedule
            .iter()
            .filter(|&&n| graph.pass(n).path.rsplit('/').next() == Some(short))
            .count()
            > 1
    };
    // `--set EFFECT.NAME` goes to an effect parameter of that name first.
    let effect_keys: Vec<String> = graph
        .params
        .iter()
        .map(|p| format!("{}.{}", p.effect, p.name))
        .collect();
    infos
        .into_iter()
        .map(|p| {
            let short = format!("{}.{}", p.pass_name, p.name);
            let key = if shared(&p.pass_name) || effect_keys.contains(&short) {
                format!("{}.{}", p.pass, p.name)
            } else {
                short
            };
            (key, p)
        })
        .collect()
}

fn describe(graph: &fxgraph::graph::Graph) {
    for (name, desc) in &graph.descriptions {
        outln!("effect {name}");
        for line in desc.lines() {
            outln!("  {line}");
        }
    }
    outln!("passes (in execution order):");
    for &n in &graph.schedule {
        let p = graph.pass(n);
        let inputs: Vec<String> = p
            .inputs
            .iter()
            .enumerate()
            .map(|(i, inp)| format!("{}={}", inp.name, graph.label(graph.input_source(n, i))))
            .collect();
        outln!(
            "  {:<28} SHADER.{:<16} {}",
            p.path,
            p.shader,
            inputs.join(" ")
        );
    }
    if graph.params.is_empty() {
        outln!("parameters: none");
    } else {
        outln!("parameters:");
        for p in &graph.params {
            let range = p
                .range
                .map(|(a, b)| format!(" range [{}, {}]", format_value(&[a]), format_value(&[b])))
                .unwrap_or_default();
            let choices = match &p.ty {
                fxgraph::script::types::ParamType::Enum(v) => format!(" one of {}", v.join("|")),
                _ => String::new(),
            };
            // ENUM values by name, BOOL as true/false.
            let show = |v: &[f64]| match &p.ty {
                fxgraph::script::types::ParamType::Enum(names) => names
                    .get(v[0] as usize)
                    .cloned()
                    .unwrap_or_else(|| format_value(v)),
                fxgraph::script::types::ParamType::Bool => (v[0] != 0.0).to_string(),
                _ => format_value(v),
            };
            outln!(
                "  {}.{:<14} {:<5} = {:<10} (default {}){range}{choices}  {}",
                p.effect,
                p.name,
                p.ty.name(),
                show(&p.value),
                show(&p.default),
                p.description
            );
        }
    }
    let rows = pass_param_rows(graph);
    if rows.is_empty() {
        outln!("pass parameters: none");
    } else {
        outln!("pass parameters (--set PASS.NAME=VALUE):");
        let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0).max(20);
        for (key, p) in rows {
            let default = p
                .default
                .as_ref()
                .map_or_else(|| "none".to_string(), |d| format_value(d));
            let value = p
                .set
                .as_ref()
                .or(p.default.as_ref())
                .map_or_else(|| "-".to_string(), |v| format_value(v));
            let range = p
                .range
                .map(|(a, b)| format!(" range [{}, {}]", format_value(&[a]), format_value(&[b])))
                .unwrap_or_default();
            let by_effect = if p.set.is_some() {
                " (set by the effect)"
            } else {
                ""
            };
            outln!(
                "  {key:<width$} {:<9} = {value:<10} (default {default}){range}{by_effect}  {}",
                p.ty.wgsl(),
                p.description
            );
        }
    }
    if graph.has_feedback() {
        outln!("temporal: uses feedback (earlier output frames); a sharded sequence run needs warm-up frames");
    }
    if graph.latency > 0 || graph.history > 0 {
        outln!(
            "temporal: reads {} earlier and {} later input frames (latency {})",
            graph.history,
            graph.latency,
            graph.latency
        );
    }
}

fn print_timings(r: &JobReport) {
    outln!(
        "adapter: {} ({})  image {}x{}",
        r.adapter,
        r.backend,
        r.width,
        r.height
    );
    outln!(
        "{:<32} {:>11} {:<10} {:>9} {:>9}",
        "pass",
        "size",
        "format",
        "gpu ms",
        "cpu ms"
    );
    for p in &r.passes {
        let gpu = p
            .gpu_ms
            .map(|g| format!("{g:.2}"))
            .unwrap_or_else(|| "-".into());
        outln!(
            "{:<32} {:>11} {:<10} {:>9} {:>9.2}",
            p.path,
            format!("{}x{}", p.width, p.height),
            p.format,
            gpu,
            p.cpu_ms
        );
    }
    outln!(
        "compile {:.1} ms | decode {:.1} | device {:.1} | pipelines {:.1} | upload {:.1} | passes {:.1} | readback {:.1} | encode {:.1} | total {:.1} ms",
        r.compile_ms, r.decode_ms, r.device_ms, r.pipeline_ms, r.upload_ms, r.passes_ms, r.readback_ms, r.encode_ms, r.total_ms
    );
    let mib = |b: u64| b as f64 / 1048576.0;
    outln!(
        "transient textures: peak {:.2} MiB (lower bound {:.2}, naive {:.2})",
        mib(r.peak_bytes),
        mib(r.lower_bound_bytes),
        mib(r.naive_bytes)
    );
}

/// `fxrun EFFECT -i 'in/%04d.png' -o 'out/%04d.png'` and `-i - -o -` (y4m streams).
fn run_sequence_cli(cli: &Cli, ispec: SequenceSpec, ospec: SequenceSpec) -> Result<(), Fail> {
    if cli.rate == 0 || cli.rate > 4 {
        return Err(rejected(format!("--rate {}: expected 1 to 4", cli.rate)));
    }
    let mut effect = Effect::compile(&cli.effects, &cli.set)?;
    if !effect.warnings.is_empty() {
        eprint!("{}", effect.warnings.render(&effect.sources));
    }
    let (history, latency) = (effect.graph.history as u64, effect.graph.latency as u64);
    let range = match &cli.frames {
        Some(f) => Some(parse_frames(f).map_err(|e| rejected(format!("--frames {f}: {e}")))?),
        None => None,
    };
    let mut fps = cli.fps.unwrap_or(25.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(rejected(format!(
            "--fps {fps}: expected a number above 0, at most 1000"
        )));
    }
    let load = fxgraph::io::LoadOptions {
        assume_linear: cli.assume_linear,
    };
    // Source: files (with the context frames a slice needs) or a y4m stream.
    let mut y4m_template = None;
    let mut emit = None;
    let source: Box<dyn FrameSource> = match &ispec {
        SequenceSpec::Stdin => {
            let stdin = std::io::BufReader::with_capacity(1 << 20, std::io::stdin());
            let reader = fxgraph::io::y4m::Y4mReader::new(stdin, "stdin")
                .map_err(|e| rejected(e.to_string()))?;
            let header = reader.header().clone();
            if cli.fps.is_none() && header.fps.1 > 0 {
                fps = header.fps.0 as f64 / header.fps.1 as f64;
            }
            let conversion = fxgraph::io::y4m::YuvConversion::for_header(&header);
            y4m_template = Some((header, conversion));
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
            Box::new(Y4mSource {
                reader,
                conversion,
                skip,
                last,
            })
        }
        SequenceSpec::Stdout => return Err(rejected("`-` as an input reads stdin; use -i - ")),
        spec => {
            let seq = InputSequence::open(spec).map_err(RunError::from)?;
            let all = &seq.frames;
            let (lo, hi) = match range {
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
            };
            let mut lo = lo;
            if cli.skip_existing {
                if let Ok(out) = OutputPattern::new(&ospec) {
                    match all
                        .iter()
                        .map(|f| f.0)
                        .filter(|n| *n >= lo && *n <= hi)
                        .find(|n| !out.exists(*n))
                    {
                        Some(first_missing) => lo = first_missing,
                        None => {
                            eprintln!("fxrun: every output frame exists already (--skip-existing)");
                            return Ok(());
                        }
                    }
                }
            }
            emit = Some((lo, hi));
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
            Box::new(FilesSource::new(all[from..=to].to_vec(), load))
        }
    };
    // Sink: numbered files or a y4m stream; the output texture format follows.
    let (sink, output_format): (Box<dyn FrameSink>, _) = match &ospec {
        SequenceSpec::Stdout => {
            let (mut header, conversion) = match y4m_template.clone() {
                Some(t) => t,
                None => {
                    let h =
                        fxgraph::io::y4m::Y4mHeader::new(1, 1, fxgraph::io::y4m::Chroma::C420Jpeg);
                    let c = fxgraph::io::y4m::YuvConversion::for_header(&h);
                    (h, c)
                }
            };
            header.fps = (header.fps.0.max(1) * cli.rate, header.fps.1.max(1));
            if cli.rate > 1 || effect.graph.params.iter().any(|p| p.name == "field_order") {
                header.interlace = fxgraph::io::y4m::Interlace::Progressive;
            }
            let sink = Y4mSink {
                inner: Some(std::io::BufWriter::with_capacity(
                    1 << 20,
                    std::io::stdout(),
                )),
                writer: None,
                template: header,
                conversion,
                name: "stdout".into(),
            };
            (
                Box::new(sink) as Box<dyn FrameSink>,
                fxgraph::script::types::Format::Rgba8Srgb,
            )
        }
        SequenceSpec::Stdin => return Err(rejected("`-` as an output writes stdout; use -o -")),
        spec => {
            let pattern = OutputPattern::new(spec).map_err(RunError::from)?;
            let _ = fxgraph::io::sequence::remove_stale_temporaries(pattern.dir());
            let probe = pattern.path_for(0);
            let format = output_format_for(&probe, cli.bit_depth, cli.assume_linear)
                .map_err(RunError::from)?;
            let save = fxgraph::io::SaveOptions {
                bit_depth: cli.bit_depth,
                assume_linear: cli.assume_linear,
            };
            (
                Box::new(FilesSink { pattern, save }) as Box<dyn FrameSink>,
                format,
            )
        }
    };
    // An interlaced y4m input sets the field order of effects that take one.
    if let Some((h, _)) = &y4m_template {
        use fxgraph::io::y4m::Interlace;
        let order = match h.interlace {
            Interlace::TopFieldFirst => Some("tff"),
            Interlace::BottomFieldFirst => Some("bff"),
            _ => None,
        };
        let has_param = effect.graph.params.iter().any(|p| p.name == "field_order");
        let user_set = cli.set.iter().any(|s| {
            s.split('=')
                .next()
                .is_some_and(|k| k.ends_with("field_order"))
        });
        if let (Some(order), true, false) = (order, has_param, user_set) {
            let mut set = cli.set.clone();
            set.push(format!("field_order={order}"));
            effect = Effect::compile(&cli.effects, &set)?;
        }
    }
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let opts = SequenceOptions {
        output_format,
        assume_linear: cli.assume_linear,
        rate: cli.rate,
        fps,
        emit,
        queue: cli.queue.max(1),
        timings: cli.timings,
    };
    let mut engine = Engine::new(
        fxgraph::gpu::context::GpuContext::new(&adapter_choice(&cli.adapter))
            .map_err(RunError::from)?,
    );
    let tty = std::io::stderr().is_terminal();
    let progress = |p: Progress| {
        if !tty {
            return;
        }
        let secs = p.elapsed.as_secs_f64().max(1e-6);
        let rate = p.done as f64 / secs;
        let line = match p.total {
            Some(t) if t > 0 => {
                let frac = p.done as f64 / t as f64;
                let bar: String = (0..30)
                    .map(|i| if (i as f64) < frac * 30.0 { '#' } else { '.' })
                    .collect();
                let eta = (t.saturating_sub(p.done)) as f64 / rate.max(1e-6);
                format!(
                    "\r[{bar}] {}/{t} frames  {rate:.1} fps  ETA {:02}:{:02} ",
                    p.done,
                    (eta as u64) / 60,
                    (eta as u64) % 60
                )
            }
            _ => format!("\r{} frames  {rate:.1} fps ", p.done),
        };
        let _ = std::io::stderr().write_all(line.as_bytes());
    };
    let result = run_sequence(
        &mut engine,
        &mut effect,
        source,
        sink,
        &opts,
        None,
        stop.clone(),
        progress,
    );
    if tty {
        eprintln!();
    }
    let report = result?;
    if cli.timings {
        let (d, g, e) = report.utilisation();
        eprintln!(
            "adapter: {}  frames: {} in, {} out  wall {:.1} ms  {:.2} fps",
            report.adapter, report.frames_in, report.frames_out, report.wall_ms, report.fps
        );
        eprintln!(
            "stage busy: decode {:.0} ms ({:.0}%), gpu {:.0} ms ({:.0}%), encode {:.0} ms ({:.0}%); the encoder waited {:.0} ms for the GPU  (frames held at most: {})",
            report.decode_busy_ms, d * 100.0, report.gpu_busy_ms, g * 100.0, report.encode_busy_ms, e * 100.0, report.readback_wait_ms, report.frames_held_max
        );
        for p in &report.passes {
            let gpu = p
                .gpu_ms
                .map(|g| format!("{g:.2}"))
                .unwrap_or_else(|| "-".into());
            eprintln!(
                "  {:<32} {:>11} {:<10} gpu {:>8} ms",
                p.path,
                format!("{}x{}", p.width, p.height),
                p.format,
                gpu
            );
        }
    }
    if let Some(path) = &cli.timings_json {
        write_json(path, &report)?;
    }
    if report.interrupted {
        return Err(Fail { code: 130, message: format!("interrupted after {} frames; completed frames are intact (rerun with --skip-existing to resume)", report.frames_out) });
    }
    Ok(())
}

fn run_scene_cli(cli: &Cli) -> Result<(), Fail> {
    use fxgraph::deferred::job::{run_scene_job, SceneJob, DEFAULT_CHAIN, DEFAULT_CHAIN_SETTINGS};
    if cli.input.is_some() {
        return Err(rejected("--scene renders the input: give no -i"));
    }
    if cli.output.is_none() && cli.gbuffer.is_none() && !cli.describe_materials {
        return Err(rejected(
            "--scene needs -o OUTPUT, --gbuffer DIR or --describe-materials",
        ));
    }
    let (width, height) = match &cli.size {
        Some(s) => parse_size(s)?,
        None => (1280, 720),
    };
    let technique = cli
        .renderer
        .parse()
        .map_err(|e: String| rejected(format!("--renderer {}: {e}", cli.renderer)))?;
    let variants = cli
        .variants
        .parse()
        .map_err(|e: String| rejected(format!("--variants {}: {e}", cli.variants)))?;
    let material_map = cli
        .material
        .iter()
        .map(|m| {
            m.split_once('=')
                .map(|(a, b)| (a.trim().to_string(), b.trim().to_string()))
                .filter(|(a, b)| !a.is_empty() && !b.is_empty())
                .ok_or_else(|| {
                    rejected(format!(
                        "--material {m}: expected SCENE_MATERIAL=DEFINITION"
                    ))
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let ambient = match &cli.ambient {
        None => None,
        Some(a) => {
            let v: Vec<f32> = a
                .split(',')
                .map(|x| x.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| rejected(format!("--ambient {a}: expected V or R,G,B (numbers)")))?;
            let rgb = match v.as_slice() {
                [x] => [*x; 3],
                [r, g, b] => [*r, *g, *b],
                _ => return Err(rejected(format!("--ambient {a}: expected V or R,G,B"))),
            };
            if rgb.iter().any(|x| !x.is_finite() || *x < 0.0) {
                return Err(rejected(format!(
                    "--ambient {a}: values must be finite and not negative"
                )));
            }
            Some(rgb)
        }
    };
    let default_chain = cli.effects.is_empty() && cli.output.is_some();
    let effects = if default_chain {
        DEFAULT_CHAIN.iter().map(|s| s.to_string()).collect()
    } else {
        cli.effects.clone()
    };
    let mut overrides: Vec<String> = if default_chain {
        DEFAULT_CHAIN_SETTINGS
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        Vec::new()
    };
    overrides.extend(cli.set.iter().cloned());
    let job = SceneJob {
        scene: cli.scene.clone().unwrap_or_else(|| "builtin:room".into()),
        width,
        height,
        camera: cli.camera.clone(),
        lights: cli.lights,
        seed: cli.seed,
        technique,
        effects,
        overrides,
        output: cli.output.clone(),
        bit_depth: cli.bit_depth,
        gbuffer: cli.gbuffer.clone(),
        timings: cli.timings,
        materials: cli.materials.clone(),
        material_map,
        variants,
        describe_materials: cli.describe_materials,
        ambient,
    };
    let mut engine = Engine::new(
        fxgraph::gpu::context::GpuContext::new(&adapter_choice(&cli.adapter))
            .map_err(RunError::from)?,
    );
    let report = run_scene_job(&job, &mut engine)?;
    if cli.describe_materials {
        outln!("materials ({} variants mode):", job.variants);
        for line in &report.materials {
            outln!("{line}");
        }
        outln!(
            "pipelines compiled: {}, shader modules: {}",
            report.pipelines,
            report.shader_modules
        );
    }
    if cli.timings {
        outln!(
            "adapter: {}  scene {} ({} triangles, {} lights visible)  {}x{}",
            report.adapter,
            job.scene,
            report.triangles,
            report.lights_visible,
            width,
            height
        );
        for (name, ms) in &report.render_passes {
            outln!("  render {name:<26} gpu {ms:>8.2} ms");
        }
        for p in &report.effect_passes {
            let gpu = p
                .gpu_ms
                .map(|g| format!("{g:.2}"))
                .unwrap_or_else(|| "-".into());
            outln!("  effect {:<26} gpu {:>8} ms", p.path, gpu);
        }
        outln!(
            "load {:.1} ms | render cpu {:.1} gpu {} | effects {:.1} | readback {:.1} | encode {:.1} | total {:.1} ms",
            report.load_ms,
            report.render_cpu_ms,
            report.render_gpu_ms.map(|g| format!("{g:.1}")).unwrap_or_else(|| "-".into()),
            report.effects_ms,
            report.readback_ms,
            report.encode_ms,
            report.total_ms
        );
    }
    if let Some(path) = &cli.timings_json {
        write_json(path, &report)?;
    }
    Ok(())
}

/// Write `value` as pretty JSON to `path`, atomically (`--timings-json`).
fn write_json(path: &std::path::Path, value: &impl serde::Serialize) -> Result<(), Fail> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Fail {
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
