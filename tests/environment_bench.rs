//! The cost of image-based lighting (run by `bench/environment.sh`, ignored in
//! the normal test run; no timing is asserted):
//!
//! 1. prefiltering time per map: every map of the corpus (`../shared/corpus/hdri`,
//!    1024×512), on a renderer whose pipelines and DFG table already exist (a
//!    fxrun run pays those once more: reported apart), median of 3;
//! 2. the per-frame GPU time of the environment term at 1920×1080: the same
//!    scene rendered with and without an environment (background colour in both),
//!    frames interleaved, medians of `FX_BENCH_FRAMES` (5).

use crate::common;

use fxgraph::gpu::context::GpuTimer;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::{Environment, EnvironmentSource, Scene};
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
#[ignore]
fn environment_benchmark() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let frames: usize = std::env::var("FX_BENCH_FRAMES").map_or(5, |s| s.parse().unwrap());
    let mut report = String::new();
    // 1. prefiltering
    let studio = Environment::new(EnvironmentSource::Studio);
    let mut room = Scene::load("builtin:room").unwrap();
    room.set_environment(Some(studio.clone()));
    let t = Instant::now();
    let r = Renderer::new(ctx, &room, &RendererOptions::default()).unwrap();
    let first = t.elapsed().as_secs_f64() * 1e3;
    report += &format!(
        "renderer with builtin:studio (512x256), first in the process: {first:.0} ms (pipelines, DFG table {}², the studio's prefiltering {:.0} ms)\n\n",
        fxgraph::render::environment::DFG_SIZE,
        r.environment_prefiltering().0
    );
    drop(r);
    report +=
        "| map (1024x512) | prefiltering (median of 3) | load (decode, checks) |\n|---|---|---|\n";
    let dir = common::ibl::corpus("hdri");
    let mut maps: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .collect();
    maps.sort();
    for path in &maps {
        let env = Environment::new(EnvironmentSource::File(path.clone()));
        let t = Instant::now();
        env.load().unwrap();
        let load = t.elapsed().as_secs_f64() * 1e3;
        let mut runs = Vec::new();
        for _ in 0..3 {
            let mut r = Renderer::new(ctx, &room, &RendererOptions::default()).unwrap();
            r.set_environment(ctx, Some(&env)).unwrap();
            runs.push(r.environment_prefiltering().0);
        }
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!("{name}: prefiltering {runs:?} ms");
        report += &format!("| {name} | {:.0} ms | {load:.0} ms |\n", median(runs));
    }
    // 2. per-frame cost
    let Some(timer) = GpuTimer::new(ctx, 64) else {
        panic!("the adapter has no timestamp queries: no frame times");
    };
    let (w, h) = (1920, 1080);
    report += &format!(
        "\n| scene ({w}x{h}) | technique | without | with builtin:studio | ratio |\n|---|---|---|---|---|\n"
    );
    let helmet = common::ibl::corpus("gltf/FlightHelmet/FlightHelmet.gltf");
    for (name, source) in [
        ("builtin:room", "builtin:room".to_string()),
        ("FlightHelmet", helmet.display().to_string()),
    ] {
        let plain = Scene::load(&source).unwrap();
        let mut lit = plain.clone();
        lit.set_environment(Some(studio.clone()));
        // the same lights in both (the environment drops a scene's default ambient)
        let mut lit_lights = plain.clone();
        lit_lights.lights = lit.lights.clone();
        let camera = plain.default_camera();
        for technique in [Technique::Deferred, Technique::Forward] {
            let mut a = Renderer::new(ctx, &lit_lights, &RendererOptions::default()).unwrap();
            let mut b = Renderer::new(ctx, &lit, &RendererOptions::default()).unwrap();
            let (mut ta, mut tb) = (Vec::new(), Vec::new());
            for i in 0..frames + 1 {
                let (_, sa) = a
                    .render(ctx, &camera, w, h, technique, Some(&timer))
                    .unwrap();
                let (_, sb) = b
                    .render(ctx, &camera, w, h, technique, Some(&timer))
                    .unwrap();
                if i > 0 {
                    ta.push(sa.gpu_ms.unwrap());
                    tb.push(sb.gpu_ms.unwrap());
                }
            }
            eprintln!("{name} {technique}: without {ta:?}, with {tb:?}");
            let (ma, mb) = (median(ta), median(tb));
            report += &format!(
                "| {name} | {technique} | {ma:.0} ms | {mb:.0} ms | {:.2}x |\n",
                mb / ma
            );
        }
    }
    common::bench::publish(&report);
}

/// The environment term's per-frame GPU time alone (issue 29's cost check):
/// builtin:room at 1920×1080, deferred, with and without builtin:studio,
/// frames interleaved, medians of `FX_BENCH_FRAMES` (5). The timestamps are
/// the GPU's (lavapipe's), so a debug build of the test measures the same
/// work as a release one. Run: `cargo test --test scene
/// environment_bench::environment_term_cost -- --ignored --nocapture`.
#[test]
#[ignore]
fn environment_term_cost() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let frames: usize = std::env::var("FX_BENCH_FRAMES").map_or(5, |s| s.parse().unwrap());
    let Some(timer) = GpuTimer::new(ctx, 64) else {
        panic!("the adapter has no timestamp queries: no frame times");
    };
    let plain = Scene::load("builtin:room").unwrap();
    let mut lit = plain.clone();
    lit.set_environment(Some(Environment::new(EnvironmentSource::Studio)));
    let mut lit_lights = plain.clone();
    lit_lights.lights = lit.lights.clone();
    let camera = plain.default_camera();
    let mut a = Renderer::new(ctx, &lit_lights, &RendererOptions::default()).unwrap();
    let mut b = Renderer::new(ctx, &lit, &RendererOptions::default()).unwrap();
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for i in 0..frames + 1 {
        for (r, t) in [(&mut a, &mut ta), (&mut b, &mut tb)] {
            let (_, stats) = r
                .render(ctx, &camera, 1920, 1080, Technique::Deferred, Some(&timer))
                .unwrap();
            if i > 0 {
                t.push(stats.gpu_ms.unwrap());
            }
        }
    }
    let (ma, mb) = (median(ta.clone()), median(tb.clone()));
    // each frame with the environment against the frame without it just before
    // (the load of a shared machine drifts between frames)
    let pairs = median(ta.iter().zip(&tb).map(|(a, b)| b - a).collect());
    eprintln!(
        "builtin:room 1920x1080 deferred: without {ta:.0?} ms, with builtin:studio {tb:.0?} ms; medians {ma:.0} / {mb:.0} ms, environment term {:.0} ms (median of the pairs' differences {pairs:.0} ms)",
        mb - ma
    );
}
