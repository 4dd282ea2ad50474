//! `fxrun`: the deferred renderer as the input (`--scene`, or `-o OUT` alone).

use super::*;

pub(crate) fn run_scene_cli(cli: &Cli) -> Result<(), Fail> {
    use fxgraph::app::scene::run_scene_job;
    if !cli.input.is_empty() {
        return Err(rejected("--scene renders the input: give no -i"));
    }
    if cli.output.is_none() && cli.gbuffer.is_none() && !cli.describe_materials {
        return Err(rejected(
            "--scene needs -o OUTPUT, --gbuffer DIR or --describe-materials",
        ));
    }
    let job = scene_job(cli, cli.effects.is_empty() && cli.output.is_some())?;
    if cli.time.is_some() || cli.frames.is_some() {
        return run_scene_sequence_cli(cli, &job);
    }
    // A still scene writes an image: no stream colour options apply.
    super::streams::check_color_options(cli, false, false)?;
    let mut engine = open_engine(cli)?;
    let report = run_scene_job(&job, &mut engine);
    fxgraph::app::pipeline_cache::save(&engine.ctx);
    let report = report?;
    if cli.describe_materials {
        let stats = report.scene.clone().unwrap_or_default();
        outln!("materials ({} variants mode):", job.variants);
        for line in &stats.materials {
            outln!("{line}");
        }
        outln!(
            "pipelines compiled: {}, shader modules: {}",
            stats.pipelines,
            stats.shader_modules
        );
    }
    finish_report(cli, &report)?;
    Ok(())
}

/// The scene job the scene options describe (also `--view`'s scene); with
/// `default_chain`, its effects are the default chain.
pub(crate) fn scene_job(
    cli: &Cli,
    default_chain: bool,
) -> Result<fxgraph::app::scene::SceneJob, Fail> {
    use fxgraph::app::scene::{SceneJob, DEFAULT_CHAIN};
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
    let light_culling = cli
        .light_culling
        .parse()
        .map_err(|e: String| rejected(format!("--light-culling {}: {e}", cli.light_culling)))?;
    let gbuffer_layout = cli
        .gbuffer_layout
        .parse()
        .map_err(|e: String| rejected(format!("--gbuffer-layout {}: {e}", cli.gbuffer_layout)))?;
    let fog = parse_fog(cli)?;
    let material_map = parse_material_map(cli)?;
    let ambient = parse_ambient(cli)?;
    let shadows = cli
        .shadows
        .parse()
        .map_err(|e: String| rejected(format!("--shadows {}: {e}", cli.shadows)))?;
    check_shadow_size(cli)?;
    let (environment, background) = environment_options(cli)?;
    let effects = if default_chain {
        DEFAULT_CHAIN.iter().map(|s| s.to_string()).collect()
    } else {
        cli.effects.clone()
    };
    let overrides = cli.set.clone();
    let job = SceneJob {
        scene: cli.scene.clone().unwrap_or_else(|| "builtin:room".into()),
        width,
        height,
        camera: cli.camera.clone(),
        animation: cli.animation.clone(),
        looping: cli.looping,
        lights: cli.lights,
        seed: cli.seed,
        technique,
        effects,
        overrides,
        default_chain,
        output: cli.output.clone(),
        bit_depth: cli.bit_depth,
        gbuffer: cli.gbuffer.clone(),
        timings: cli.timings || cli.timings_json.is_some(),
        materials: cli.materials.clone(),
        material_map,
        variants,
        light_culling,
        gbuffer_layout,
        fog,
        describe_materials: cli.describe_materials,
        ambient,
        shadows,
        shadow_size: cli.shadow_size,
        shadow_layers: cli.shadow_layers,
        environment,
        background,
        aux: crate::aux_images(cli)?,
    };
    Ok(job)
}

/// `--fog`: the scene's fog, none without the option; every error in it reported.
fn parse_fog(cli: &Cli) -> Result<Option<fxgraph::render::fog::Fog>, Fail> {
    if cli.fog.is_empty() {
        return Ok(None);
    }
    Ok(Some(fxgraph::render::fog::Fog::parse(&cli.fog).map_err(
        |errors| {
            rejected(
                errors
                    .iter()
                    .map(|e| format!("--{e}"))
                    .collect::<Vec<_>>()
                    .join("\nfxrun: error: "),
            )
        },
    )?))
}

/// `--material SCENE_MATERIAL=DEFINITION`, each as a (name, definition) pair.
fn parse_material_map(cli: &Cli) -> Result<Vec<(String, String)>, Fail> {
    cli.material
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
        .collect()
}

/// `--ambient V` or `--ambient R,G,B`: finite, not negative.
fn parse_ambient(cli: &Cli) -> Result<Option<[f32; 3]>, Fail> {
    let Some(a) = &cli.ambient else {
        return Ok(None);
    };
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
    Ok(Some(rgb))
}

/// `--shadow-size` within what the renderer takes.
fn check_shadow_size(cli: &Cli) -> Result<(), Fail> {
    use fxgraph::render::renderer::{MAX_SHADOW_SIZE, MIN_SHADOW_SIZE};
    if !(MIN_SHADOW_SIZE..=MAX_SHADOW_SIZE).contains(&cli.shadow_size) {
        return Err(rejected(format!(
            "--shadow-size {}: must be {MIN_SHADOW_SIZE} to {MAX_SHADOW_SIZE} texels",
            cli.shadow_size
        )));
    }
    Ok(())
}

/// `--scene` with `--frames A..B` or `--time SECONDS`: a rendered sequence (or one
/// frame of it) written as numbered files, into a folder, to a y4m stream on
/// stdout, or (one frame) to one file; `--time` with `--gbuffer` and no `-o`: that
/// frame's G-buffer alone.
fn run_scene_sequence_cli(cli: &Cli, job: &fxgraph::app::SceneJob) -> Result<(), Fail> {
    use fxgraph::app::SceneTimes;
    use fxgraph::io::sequence::SequenceSpec;
    let fps = cli.fps.unwrap_or(30.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(rejected(format!(
            "--fps {fps}: expected a number above 0, at most 1000"
        )));
    }
    if cli.gbuffer.is_some() && cli.frames.is_some() {
        return Err(rejected(
            "--gbuffer writes one frame's G-buffer: use it with a still or --time, not --frames",
        ));
    }
    let times = scene_times(cli, fps)?;
    let Some(output) = &cli.output else {
        if cli.gbuffer.is_none() {
            return Err(rejected("a rendered sequence needs -o OUTPUT"));
        }
        return write_gbuffer_only(cli, job, &times);
    };
    let ospec = SequenceSpec::parse_output(&output.to_string_lossy());
    let stream = matches!(
        ospec,
        SequenceSpec::Stdout | SequenceSpec::Y4m(_) | SequenceSpec::Video(_)
    );
    super::streams::check_color_options(cli, false, stream)?;
    let Some((sink, format, first)) = open_scene_sink(cli, &ospec, output, &times, fps)? else {
        return Ok(());
    };
    let times = SceneTimes {
        frames: (first, times.frames.1),
        ..times
    };
    let report = render_frames(cli, job, &times, sink, format)?;
    finish_report(cli, &report)?;
    super::streams::check_interrupted(&report, &ospec)
}

/// `--time` with `--gbuffer` alone: that frame's G-buffer, as for a still (no
/// effects run, no image written).
fn write_gbuffer_only(
    cli: &Cli,
    job: &fxgraph::app::SceneJob,
    times: &fxgraph::app::SceneTimes,
) -> Result<(), Fail> {
    let job = fxgraph::app::SceneJob {
        effects: Vec::new(),
        ..job.clone()
    };
    let report = render_frames(
        cli,
        &job,
        times,
        Box::new(fxgraph::app::DiscardSink),
        fxgraph::script::types::Format::Rgba16f,
    )?;
    finish_report(cli, &report)?;
    if report.interrupted && report.done.is_empty() {
        return Err(Fail {
            code: 130,
            message: "interrupted before the frame's G-buffer was written".into(),
        });
    }
    Ok(())
}

/// Where a rendered sequence goes (`-o`), the output texture format, and the first
/// frame to render (after those that exist, with --skip-existing).
type SceneSink = (Box<dyn FrameSink>, fxgraph::script::types::Format, u64);

/// The sink of a rendered sequence: y4m on stdout, a .y4m or video file, one file
/// (one frame), or numbered files (a pattern or a folder); `None` when there is
/// nothing to render (the outputs exist, with --skip-existing).
fn open_scene_sink(
    cli: &Cli,
    ospec: &fxgraph::io::sequence::SequenceSpec,
    output: &std::path::Path,
    times: &fxgraph::app::SceneTimes,
    fps: f64,
) -> Result<Option<SceneSink>, Fail> {
    use fxgraph::app::{FilesSink, OutputNames};
    use fxgraph::io::sequence::{OutputPattern, SequenceSpec};
    let save = fxgraph::io::SaveOptions {
        bit_depth: cli.bit_depth,
        assume_linear: false,
    };
    let first = times.frames.0;
    match ospec {
        SequenceSpec::Stdout | SequenceSpec::Y4m(_) | SequenceSpec::Video(_) => {
            // y4m on stdout, a .y4m file or a video file (through ffmpeg); a whole
            // file is written or not: with --skip-existing an existing one is kept
            // and the run skipped, as for an image sequence's output
            if super::streams::skip_whole_file(cli, ospec) {
                return Ok(None);
            }
            let output = super::streams::stream_output(ospec).expect("a stream spec");
            let plan = super::streams::StreamPlan {
                template: None,
                video: None,
                fps,
                emit: None,
                deinterlaces: false,
                display_referred: super::streams::has_tonemap(cli),
                hdr: Default::default(),
            };
            let opened = super::streams::open_stream_output(cli, &output, &plan)?;
            Ok(Some((opened.sink, opened.texture_format, first)))
        }
        SequenceSpec::Single(path) if times.frames.0 == times.frames.1 => {
            let format = output_format_for(path, cli.bit_depth, false).map_err(RunError::from)?;
            let names = OutputNames::Named([(times.frames.0, path.clone())].into());
            Ok(Some((Box::new(FilesSink { names, save }), format, first)))
        }
        SequenceSpec::Single(path) => Err(rejected(format!(
            "-o {}: several frames need a numbered pattern (out/%04d.png), a folder, a .y4m or video file, or - (y4m)",
            path.display()
        ))),
        SequenceSpec::Stdin | SequenceSpec::Glob(_) => Err(rejected(format!(
            "-o {}: not an output for frames",
            output.display()
        ))),
        spec => {
            let pattern = match (spec, &cli.format) {
                (SequenceSpec::Dir(dir), ext) => OutputPattern::in_dir(
                    dir,
                    ext.as_deref().unwrap_or("png").trim_start_matches('.'),
                ),
                _ => OutputPattern::new(spec),
            }
            .map_err(RunError::from)?;
            let _ = fxgraph::io::sequence::remove_stale_temporaries(pattern.dir());
            let mut first = first;
            if cli.skip_existing {
                match (times.frames.0..=times.frames.1).find(|n| !pattern.exists(*n)) {
                    Some(n) => first = n,
                    None => {
                        eprintln!("fxrun: every output frame exists already (--skip-existing)");
                        return Ok(None);
                    }
                }
            }
            let format = output_format_for(&pattern.path_for(0), cli.bit_depth, false)
                .map_err(RunError::from)?;
            let sink = Box::new(FilesSink {
                names: OutputNames::Pattern(pattern),
                save,
            });
            Ok(Some((sink, format, first)))
        }
    }
}

/// The frames `--time SECONDS` or `--frames A..B` render (at `fps`).
fn scene_times(cli: &Cli, fps: f64) -> Result<fxgraph::app::SceneTimes, Fail> {
    use fxgraph::app::SceneTimes;
    use fxgraph::io::sequence::parse_frames;
    let times = match (cli.time, &cli.frames) {
        (Some(_), Some(_)) => {
            return Err(rejected(
                "--time renders one frame, --frames a sequence: give one of them",
            ))
        }
        (Some(t), None) => {
            if !(t.is_finite() && t >= 0.0) {
                return Err(rejected(format!(
                    "--time {t}: must be 0 or more seconds (frame 0 is at time 0; a scene's animation holds its first pose before its first key)"
                )));
            }
            SceneTimes::at(t, fps, cli.warmup)
        }
        (None, Some(f)) => {
            let r = parse_frames(f).map_err(|e| rejected(format!("--frames {f}: {e}")))?;
            if r.end == u64::MAX {
                return Err(rejected(format!(
                    "--frames {f}: a rendered sequence needs its last frame (A..B)"
                )));
            }
            SceneTimes {
                fps,
                frames: (r.start, r.end),
                warmup: cli.warmup,
                time: None,
            }
        }
        (None, None) => unreachable!("called with --time or --frames"),
    };
    Ok(times)
}

/// Renders `times` of the scene job into `sink` (`format`: what its files take),
/// with the progress line and Ctrl-C.
fn render_frames(
    cli: &Cli,
    job: &fxgraph::app::SceneJob,
    times: &fxgraph::app::SceneTimes,
    sink: Box<dyn FrameSink>,
    format: fxgraph::script::types::Format,
) -> Result<fxgraph::app::RunReport, Fail> {
    let mut engine = open_engine(cli)?;
    let stop = stop_flag();
    let progress = ProgressLine::new("frames");
    let result = fxgraph::app::run_scene_sequence(
        job,
        times,
        &mut engine,
        sink,
        format,
        stop,
        progress.callback(),
    );
    progress.finish();
    Ok(result?)
}

/// The environment of `--environment` (the default: [`DEFAULT_ENVIRONMENT`])
/// with `--environment-intensity`, `--environment-rotation`, `--sun`,
/// `--turbidity`, and the `--background`.
fn environment_options(
    cli: &Cli,
) -> Result<
    (
        Option<fxgraph::scene::Environment>,
        Option<fxgraph::scene::Background>,
    ),
    Fail,
> {
    use fxgraph::scene::{Background, Environment, EnvironmentSource};
    let spec = cli.environment.as_deref().unwrap_or(DEFAULT_ENVIRONMENT);
    let mut env = Environment::parse(spec).map_err(|e| rejected(format!("--environment: {e}")))?;
    if !(cli.environment_intensity.is_finite() && cli.environment_intensity >= 0.0) {
        return Err(rejected(format!(
            "--environment-intensity {}: must be finite and not negative",
            cli.environment_intensity
        )));
    }
    if !cli.environment_rotation.is_finite() {
        return Err(rejected(
            "--environment-rotation: must be a finite number of degrees",
        ));
    }
    let sky = match env.as_mut().map(|e| &mut e.source) {
        Some(EnvironmentSource::Sky(s)) => Some(s),
        _ => None,
    };
    match sky {
        Some(s) => {
            if let Some(sun) = &cli.sun {
                let v: Vec<f32> = sun
                    .split(',')
                    .map(|x| x.trim().parse::<f32>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| {
                        rejected(format!(
                            "--sun {sun}: expected ELEVATION,AZIMUTH in degrees"
                        ))
                    })?;
                let [e, a] = v.as_slice() else {
                    return Err(rejected(format!(
                        "--sun {sun}: expected ELEVATION,AZIMUTH in degrees"
                    )));
                };
                (s.elevation, s.azimuth) = (*e, *a);
            }
            if let Some(t) = cli.turbidity {
                s.turbidity = t;
            }
            s.check().map_err(rejected)?;
        }
        None if cli.sun.is_some() || cli.turbidity.is_some() => {
            return Err(rejected(
                "--sun and --turbidity set builtin:sky: add --environment builtin:sky",
            ));
        }
        None => {}
    }
    if let Some(e) = env.as_mut() {
        e.intensity = cli.environment_intensity;
        e.rotation = cli.environment_rotation;
    }
    let background = cli
        .background
        .as_deref()
        .map(Background::parse)
        .transpose()
        .map_err(|e| rejected(e.to_string()))?;
    if matches!(background, Some(Background::Environment { .. })) && env.is_none() {
        return Err(rejected(
            "--background environment needs an environment (--environment is none)",
        ));
    }
    Ok((env, background))
}

/// The environment of a scene without `--environment`: like every glTF viewer,
/// fxrun lights PBR materials with an environment by default (docs/renderer.md).
const DEFAULT_ENVIRONMENT: &str = "builtin:studio";

/// The engine of a scene job, with the pipeline cache of earlier runs attached.
fn open_engine(cli: &Cli) -> Result<Engine, RunError> {
    let mut ctx = fxgraph::gpu::context::GpuContext::new(&adapter_choice(&cli.adapter))?;
    fxgraph::app::pipeline_cache::attach(&mut ctx);
    Ok(Engine::new(ctx))
}
