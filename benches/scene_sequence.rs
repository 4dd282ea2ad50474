//! A rendered sequence's GPU time per frame against a still's, and the motion
//! vectors' cost against the G-buffer pass, at 1280x720 (FX_BENCH_SIZE=WxH) on an
//! animated skinned model (FX_BENCH_SCENE, default the corpus's RiggedSimple,
//! ../shared/corpus/gltf/animated). One renderer, one process:
//! - still: the scene at rest, no motion (what `--scene` renders for one image);
//! - sequence: frame n at n / 30 s as `--frames` renders it: the pose now and one
//!   frame earlier, instance transforms, joint matrices and morph weights written,
//!   the skinning pass, the motion-vector passes.
//!
//! Blocks of FX_BENCH_FRAMES frames (default 16) alternate still / sequence
//! FX_BENCH_ROUNDS times (default 2) so that both see the same machine load; the
//! first frame of each block is not counted (it pays the switch: a still after a
//! sequence restores the rest vertices once). Every frame's passes are timed with
//! timestamp queries. Printed: per mode the median GPU time per frame, the median
//! wall time of `render_frame` (CPU posing and recording plus the GPU, waited
//! for), the ratio sequence / still, and the median of each pass; then the motion
//! passes against the G-buffer pass. FX_BENCH_TECHNIQUE picks the technique
//! (deferred by default: its G-buffer pass is `geometry`).
//!
//!   cargo bench --bench scene_sequence      (bash bench/scene_sequence.sh)

use fxgraph::gpu::context::GpuTimer;
use fxgraph::render::{FrameMotion, Renderer, RendererOptions, Technique};
use fxgraph::scene::{CameraPath, Playback, Scene};
use std::collections::BTreeMap;
use std::time::Instant;

mod bench_env;
use bench_env::{adapter, env_or, median, size};

/// Per mode: GPU ms per frame, wall ms per frame, and per pass the GPU ms.
#[derive(Default)]
struct Samples {
    gpu: Vec<f64>,
    wall: Vec<f64>,
    passes: BTreeMap<String, Vec<f64>>,
}

fn main() {
    let Some(ctx) = adapter("scene sequence") else {
        return;
    };
    let (w, h) = size((1280, 720));
    let frames: usize = env_or("FX_BENCH_FRAMES", 16);
    let rounds: usize = env_or("FX_BENCH_ROUNDS", 2);
    let technique: Technique = std::env::var("FX_BENCH_TECHNIQUE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(Technique::Deferred);
    let scene_path = std::env::var("FX_BENCH_SCENE").unwrap_or_else(|_| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/corpus/gltf/animated/RiggedSimple/RiggedSimple.gltf"
        )
        .to_string()
    });
    let scene = match Scene::load(&scene_path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{scene_path}: {e}");
            std::process::exit(1);
        }
    };
    let Some(timer) = GpuTimer::new(&ctx, 64) else {
        println!("the adapter has no timestamp queries: no GPU times");
        return;
    };
    println!("adapter: {} ({:?})", ctx.info.name, ctx.info.backend);
    let deformed = (0..scene.instances.len())
        .filter(|&i| scene.is_deformed(i))
        .count();
    println!(
        "scene: {scene_path} ({} triangles, {} instances, {deformed} skinned or morphed), {technique}, {w}x{h}",
        scene.triangle_count(),
        scene.instances.len()
    );
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let playback = Playback::default();
    let path = CameraPath::parse(None, &scene).unwrap();
    let rest = scene.pose(0.0, &Playback::none());
    let still_camera = path.at(&scene, Some(&rest), 0.0);
    let fps = 30.0;
    let duration = scene.animation_duration(&playback).max(1.0 / fps);
    let mut modes = [
        ("still", Samples::default()),
        ("sequence", Samples::default()),
    ];
    let mut n = 0u64;
    for _ in 0..rounds {
        for (m, (_, samples)) in modes.iter_mut().enumerate() {
            for k in 0..=frames {
                let start = Instant::now();
                let (camera, motion) = if m == 0 {
                    (still_camera, FrameMotion::default())
                } else {
                    // frame n, wrapped inside the animation so it keeps moving
                    let t = (n as f64 / fps) % duration + 1.0 / fps;
                    n += 1;
                    let (pose, prev) = (
                        scene.pose(t, &playback),
                        scene.pose(t - 1.0 / fps, &playback),
                    );
                    r.set_lights(pose.lights.clone());
                    let motion = FrameMotion {
                        prev_camera: Some(path.at(&scene, Some(&prev), t - 1.0 / fps)),
                        ..FrameMotion::posed(&scene, &pose, &prev)
                    };
                    (path.at(&scene, Some(&pose), t), motion)
                };
                let (_, stats) = r
                    .render_frame(&ctx, &camera, &motion, w, h, technique, Some(&timer))
                    .unwrap();
                let wall = start.elapsed().as_secs_f64() * 1e3;
                if k == 0 {
                    continue;
                }
                samples.gpu.push(stats.gpu_ms.unwrap_or(f64::NAN));
                samples.wall.push(wall);
                for (name, ms) in stats.pass_ms {
                    samples.passes.entry(name).or_default().push(ms);
                }
            }
        }
    }
    let counted = frames * rounds;
    println!("median over {counted} frames per mode ({rounds} rounds of {frames}, each after one uncounted frame):");
    let mut totals = Vec::new();
    for (name, s) in &modes {
        let (g, wall) = (median(s.gpu.clone()), median(s.wall.clone()));
        totals.push(g);
        println!("  {name:<9} GPU {g:>8.3} ms/frame   render_frame wall {wall:>8.3} ms/frame");
        for (pass, v) in &s.passes {
            let note = if v.len() < counted {
                format!(" (in {} of {counted} frames)", v.len())
            } else {
                String::new()
            };
            println!("      {pass:<36} {:>8.3} ms{note}", median(v.clone()));
        }
    }
    println!(
        "sequence / still GPU time per frame: {:.3} (target <= 1.15)",
        totals[1] / totals[0]
    );
    let seq = &modes[1].1;
    // the still and the sequence frames show different poses (different pixel
    // coverage): the passes only a sequence runs measure its own cost directly
    let extra: f64 = ["skinning", "motion (objects)"]
        .iter()
        .filter_map(|p| seq.passes.get(*p).map(|v| median(v.clone())))
        .sum();
    println!(
        "sequence-only passes (skinning, motion (objects)): {extra:.3} ms, {:.2} % of a sequence frame",
        100.0 * extra / totals[1]
    );
    let pass = |name: &str| seq.passes.get(name).map(|v| median(v.clone()));
    let gbuffer = match technique {
        Technique::Deferred => "geometry",
        Technique::LightPrepass => "depth+normals",
        Technique::Forward => "forward",
        other => {
            println!("no G-buffer pass known for {other:?}: no motion/skinning ratio");
            return;
        }
    };
    if let (Some(g), Some(m)) = (pass(gbuffer), pass("motion (objects)")) {
        println!(
            "motion (objects) / {gbuffer}: {:.3} ({m:.3} / {g:.3} ms; target <= 0.10)",
            m / g
        );
        if let Some(s) = pass("skinning") {
            println!(
                "skinning / {gbuffer}: {:.3}; skinning + motion (objects) / {gbuffer}: {:.3}",
                s / g,
                (s + m) / g
            );
        }
    }
}
