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
    let mut engine = Engine::new(
        fxgraph::gpu::context::GpuContext::new(&adapter_choice(&cli.adapter))
            .map_err(RunError::from)?,
    );
    let report = run_scene_job(&job, &mut engine)?;
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
    print_report(cli, &report);
    if let Some(path) = &cli.timings_json {
        write_json(path, &report)?;
    }
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
    let fog = if cli.fog.is_empty() {
        None
    } else {
        Some(
            fxgraph::render::fog::Fog::parse(&cli.fog).map_err(|errors| {
                rejected(
                    errors
                        .iter()
                        .map(|e| format!("--{e}"))
                        .collect::<Vec<_>>()
                        .join("\nfxrun: error: "),
                )
            })?,
        )
    };
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
    let shadows = cli
        .shadows
        .parse()
        .map_err(|e: String| rejected(format!("--shadows {}: {e}", cli.shadows)))?;
    use fxgraph::render::renderer::{MAX_SHADOW_SIZE, MIN_SHADOW_SIZE};
    if !(MIN_SHADOW_SIZE..=MAX_SHADOW_SIZE).contains(&cli.shadow_size) {
        return Err(rejected(format!(
            "--shadow-size {}: must be {MIN_SHADOW_SIZE} to {MAX_SHADOW_SIZE} texels",
            cli.shadow_size
        )));
    }
    let effects = if default_chain {
        DEFAULT_CHAIN.iter().map(|s| s.to_string()).collect()
    } else {
        cli.effects.clone()
    };
    let mut overrides: Vec<String> = Vec::new();
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
        default_chain,
        output: cli.output.clone(),
        bit_depth: cli.bit_depth,
        gbuffer: cli.gbuffer.clone(),
        timings: cli.timings,
        materials: cli.materials.clone(),
        material_map,
        variants,
        light_culling,
        fog,
        describe_materials: cli.describe_materials,
        ambient,
        shadows,
        shadow_size: cli.shadow_size,
        shadow_layers: cli.shadow_layers,
    };
    Ok(job)
}
