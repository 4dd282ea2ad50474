//! Shadow maps (src/render/shadows.rs, shadow_pass.rs, shaders/shadow.wgsl) on
//! a box floating over a plane, no ambient light, white Lambertian material:
//! the shadow's position against a CPU ray-cast oracle, the shadowed radiance
//! near zero, the lit radiance at the analytic value E · albedo / π · cos θ, the
//! three techniques alike, `off` as the unshadowed image, the layer budget, and
//! the CLI's checks of the options. The scene and the ray-cast oracle are in
//! `common/shadow_scene.rs`.
//!
//! GPU tests skip without an adapter unless FX_REQUIRE_GPU=1.

use crate::common;
use crate::common::shadow_scene;

use common::renders::assert_psnr;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::renderer::DEFAULT_SHADOW_SIZE;
use fxgraph::render::{RenderStats, Renderer, RendererOptions, ShadowMode, Technique};
use fxgraph::scene::{Light, Scene};
use glam::Vec3;
use shadow_scene::*;
use std::f32::consts::PI;
use std::process::Command;

/// Shadow maps of 1024² (the default 2048² costs llvmpipe time for nothing here).
fn options(shadows: ShadowMode) -> RendererOptions {
    RendererOptions {
        shadows,
        shadow_size: 1024,
        ..Default::default()
    }
}

fn gpu() -> Option<std::sync::MutexGuard<'static, fxgraph::gpu::executor::Engine>> {
    common::engine()
}

fn render(
    scene: &Scene,
    opts: &RendererOptions,
    technique: Technique,
) -> (Vec<[f32; 4]>, RenderStats) {
    let engine = gpu().expect("checked by the caller");
    let ctx = &engine.ctx;
    let mut r = Renderer::new(ctx, scene, opts).unwrap();
    let (out, stats) = r
        .render(ctx, &camera(), W, H, technique, None)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    (read_rgba_f32(ctx, &out.scene).unwrap(), stats)
}

#[test]
fn directional_light_shadow_matches_the_ray_cast_oracle() {
    if gpu().is_none() {
        return;
    }
    let light = directional();
    for mode in [ShadowMode::Pcf, ShadowMode::Hard] {
        let (pixels, stats) = render(&scene(light.clone()), &options(mode), Technique::Deferred);
        assert_eq!(stats.shadow_layers, 4, "four cascades");
        assert_eq!(stats.shadow_map_bytes, 1024 * 1024 * 4 * 4);
        check_against_oracle(&format!("directional {mode}"), &pixels, &light);
    }
}

/// The scene lit by `light`, rendered deferred with PCF shadows: the shadow map
/// has `layers` layers (`what` they are), and the image matches the ray-cast oracle.
fn pcf_shadow_matches_the_oracle(name: &str, light: Light, layers: usize, what: &str) {
    if gpu().is_none() {
        return;
    }
    let options = options(ShadowMode::Pcf);
    let (pixels, stats) = render(&scene(light.clone()), &options, Technique::Deferred);
    assert_eq!(stats.shadow_layers, layers, "{what}");
    check_against_oracle(name, &pixels, &light);
}

#[test]
fn spot_light_shadow_matches_the_ray_cast_oracle() {
    pcf_shadow_matches_the_oracle("spot", spot(), 1, "one layer");
}

#[test]
fn point_light_shadow_matches_the_ray_cast_oracle() {
    pcf_shadow_matches_the_oracle("point", point(), 6, "six cube faces");
}

#[test]
fn techniques_agree_with_shadows() {
    if gpu().is_none() {
        return;
    }
    for (name, light) in [
        ("directional", directional()),
        ("point", point()),
        ("spot", spot()),
    ] {
        let s = scene(light.clone());
        let (reference, _) = render(&s, &options(ShadowMode::Pcf), Technique::Deferred);
        for t in [Technique::LightPrepass, Technique::Forward] {
            let (pixels, _) = render(&s, &options(ShadowMode::Pcf), t);
            assert_psnr(
                &format!("{name}: deferred vs {t}"),
                &reference,
                &pixels,
                40.0,
            );
            check_against_oracle(&format!("{name} {t}"), &pixels, &light);
        }
    }
}

#[test]
fn shadows_off_gives_the_unshadowed_image() {
    if gpu().is_none() {
        return;
    }
    let light = directional();
    let truth = oracle(&light);
    for t in Technique::ALL {
        let (pixels, stats) = render(&scene(light.clone()), &options(ShadowMode::Off), t);
        assert_eq!((stats.shadow_layers, stats.shadow_map_bytes), (0, 0));
        // every ground pixel, the oracle's shadow included, has the lit value
        let (mut n, mut in_shadow) = (0, 0);
        for (g, p) in truth.iter().zip(&pixels) {
            let Some(g) = g else { continue };
            assert!(
                (p[1] - g.lit).abs() <= 0.03 * g.lit + 1e-3,
                "{t}: {} vs {}",
                p[1],
                g.lit
            );
            n += 1;
            in_shadow += usize::from(g.shadowed);
        }
        assert!(
            n > 1000 && in_shadow > 100,
            "{t}: {n} ground pixels, {in_shadow} in the box's shadow"
        );
    }
}

#[test]
fn layer_budget_drops_the_least_important_lights() {
    if gpu().is_none() {
        return;
    }
    let mut s = scene(directional());
    s.lights.push(point());
    // 4 cascades fit, the point light's 6 faces do not
    let opts = RendererOptions {
        shadow_budget: 5,
        ..options(ShadowMode::Pcf)
    };
    let (_, stats) = render(&s, &opts, Technique::Forward);
    assert_eq!(stats.shadow_layers, 4);
    let (_, stats) = render(&s, &options(ShadowMode::Pcf), Technique::Forward);
    assert_eq!(stats.shadow_layers, 10);
    // the default size
    let (_, stats) = render(
        &scene(spot()),
        &RendererOptions::default(),
        Technique::Forward,
    );
    let size = u64::from(DEFAULT_SHADOW_SIZE);
    assert_eq!(stats.shadow_map_bytes, size * size * 4);
}

#[test]
fn renderer_rejects_bad_shadow_sizes() {
    let Some(engine) = gpu() else { return };
    let s = scene(directional());
    for size in [5, 100_000] {
        let opts = RendererOptions {
            shadow_size: size,
            ..Default::default()
        };
        let e = Renderer::new(&engine.ctx, &s, &opts)
            .err()
            .expect("rejected");
        assert!(e.to_string().contains("shadow map size"), "{e}");
    }
    let opts = RendererOptions {
        shadow_budget: 1 << 20,
        ..Default::default()
    };
    let e = Renderer::new(&engine.ctx, &s, &opts)
        .err()
        .expect("rejected");
    assert!(e.to_string().contains("layers"), "{e}");
}

#[test]
fn cli_rejects_bad_shadow_options() {
    let out = std::env::temp_dir().join("fx_shadow_cli_test.png");
    for args in [
        &["--shadow-size", "5"][..],
        &["--shadow-size", "9000"][..],
        &["--shadows", "soft"][..],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_fxrun"))
            .args(["--scene", "builtin:room", "-o"])
            .arg(&out)
            .args(args)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(args[0]), "{args:?}: {err}");
    }
}

#[test]
fn timed_frames_time_the_shadow_maps_as_one_pass() {
    let Some(engine) = gpu() else { return };
    let ctx = &engine.ctx;
    let Some(timer) = fxgraph::gpu::context::GpuTimer::new(ctx, 16) else {
        eprintln!("skipping: the adapter has no timestamp queries");
        return;
    };
    // six layers: the middle passes write no timestamps (wgpu refuses a pass
    // with an empty timestamp set), the first and last bracket them all
    let mut r = Renderer::new(ctx, &scene(point()), &options(ShadowMode::Pcf)).unwrap();
    let (_, stats) = r
        .render(ctx, &camera(), W, H, Technique::Deferred, Some(&timer))
        .unwrap();
    let names: Vec<&str> = stats.pass_ms.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names[0], "shadow maps (6 layers)", "{names:?}");
    assert!(stats.pass_ms[0].1 >= 0.0);
}

#[test]
fn a_user_lighting_shader_is_shadowed_too() {
    if gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("wrap_lambert.wgsl"),
        include_str!("../docs/examples/wrap_lambert.wgsl"),
    )
    .unwrap();
    let text = "MATERIAL.wrapped = { SURFACE = SHADER.standard { base_color = (1, 1, 1, 1) } LIGHTING = SHADER.wrap_lambert { wrap = 0.3 } }\n";
    let file =
        fxgraph::scene::material_file::load_materials("wrapped.fx", text, Some(dir.path()), 0)
            .unwrap_or_else(|e| panic!("{e}"));
    let light = directional();
    let mut s = scene(light.clone());
    s.materials = file.materials;
    let truth = oracle_wrap(&light, 0.3);
    for t in Technique::ALL {
        let (pixels, _) = render(&s, &options(ShadowMode::Pcf), t);
        check_against(&format!("wrap_lambert {t}"), &pixels, &truth);
    }
}

/// The shadow benchmark (not a test): frame times of a scene with shadows off,
/// hard and PCF, median of 5 frames after a warm-up, GPU pass times when the
/// adapter has timestamps, else wall time; the modes are interleaved:
/// `cargo test --test scene -- --ignored shadows::shadow_benchmark --nocapture`.
/// Environment: FX_SHADOW_BENCH_SCENE (default the corpus Cornell box),
/// FX_SHADOW_BENCH_SIZE=WxH (default 1920x1080), FX_SHADOW_BENCH_TECHNIQUE.
#[test]
#[ignore]
fn shadow_benchmark() {
    let Some(engine) = gpu() else { return };
    let ctx = &engine.ctx;
    let path = std::env::var("FX_SHADOW_BENCH_SCENE").unwrap_or_else(|_| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/corpus/gltf/CornellBox.glb"
        )
        .into()
    });
    let (w, h) = std::env::var("FX_SHADOW_BENCH_SIZE")
        .ok()
        .and_then(|s| {
            let (w, h) = s.split_once('x')?;
            Some((w.parse().ok()?, h.parse().ok()?))
        })
        .unwrap_or((1920, 1080));
    let technique: Technique = std::env::var("FX_SHADOW_BENCH_TECHNIQUE")
        .map(|t| t.parse().unwrap())
        .unwrap_or(Technique::Deferred);
    let mut s = Scene::load(&path).unwrap();
    s.ensure_lights();
    let cam = s.default_camera();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let timer = fxgraph::gpu::context::GpuTimer::new(ctx, 32);
    println!(
        "{path} {w}x{h} {technique}, adapter {}, {} lights, median of 5 frames ({}):",
        ctx.info.name,
        s.lights.len(),
        if timer.is_some() {
            "GPU timestamps; wall = render() incl. the timestamp read-back"
        } else {
            "wall"
        }
    );
    // One renderer per mode, warmed up, then the modes interleaved frame by
    // frame: load from other processes spreads over all three alike.
    let mut renderers: Vec<Renderer> = ShadowMode::ALL
        .iter()
        .map(|&mode| {
            let opts = RendererOptions {
                shadows: mode,
                ..Default::default()
            };
            let mut r = Renderer::new(ctx, &s, &opts).unwrap();
            r.render(ctx, &cam, w, h, technique, timer.as_ref())
                .unwrap();
            r
        })
        .collect();
    let mut samples = vec![(Vec::new(), Vec::new(), Vec::new(), Vec::new()); 3];
    let mut layers = [0; 3];
    for _round in 0..5 {
        for (m, r) in renderers.iter_mut().enumerate() {
            let t = std::time::Instant::now();
            let (out, stats) = r
                .render(ctx, &cam, w, h, technique, timer.as_ref())
                .unwrap();
            if timer.is_none() {
                read_rgba_f32(ctx, &out.scene).unwrap();
            }
            let wall = t.elapsed().as_secs_f64() * 1e3;
            let pass = |prefix: &str| {
                stats
                    .pass_ms
                    .iter()
                    .find(|(n, _)| n.starts_with(prefix))
                    .map_or(0.0, |p| p.1)
            };
            layers[m] = stats.shadow_layers;
            samples[m].0.push(stats.gpu_ms.unwrap_or(f64::NAN));
            samples[m].1.push(pass("shadow maps"));
            samples[m].2.push(pass("lights"));
            samples[m].3.push(wall);
        }
    }
    for (m, (gpu_ms, shadow_ms, light_ms, wall_ms)) in samples.into_iter().enumerate() {
        println!(
            "  shadows {:<4}: gpu {:>7.1} ms (shadow maps {:>6.1} ms for {} layers, light pass {:>6.1} ms)  wall {:>7.1} ms",
            ShadowMode::ALL[m].name(),
            median(gpu_ms),
            median(shadow_ms),
            layers[m],
            median(light_ms),
            median(wall_ms)
        );
    }
}

#[test]
fn shadows_work_with_every_light_culling() {
    if gpu().is_none() {
        return;
    }
    use fxgraph::render::renderer::LightCulling;
    let light = point();
    for culling in [
        LightCulling::Clustered,
        LightCulling::Volumes,
        LightCulling::None,
    ] {
        let opts = RendererOptions {
            light_culling: culling,
            ..options(ShadowMode::Pcf)
        };
        for t in [Technique::Deferred, Technique::Forward] {
            let (pixels, _) = render(&scene(light.clone()), &opts, t);
            check_against_oracle(&format!("point {culling:?} {t}"), &pixels, &light);
        }
    }
}

#[test]
fn grazing_light_has_no_acne_and_a_long_shadow() {
    if gpu().is_none() {
        return;
    }
    // 71° from the ground's normal: the lit ground must stay at its analytic
    // value (no self-shadowing), the long shadow where the oracle puts it
    let light = Light::directional(Vec3::new(1.0, -0.35, 0.2), Vec3::ONE, PI);
    for mode in [ShadowMode::Pcf, ShadowMode::Hard] {
        for t in Technique::ALL {
            let (pixels, _) = render(&scene(light.clone()), &options(mode), t);
            check_against_oracle(&format!("grazing {mode} {t}"), &pixels, &light);
        }
    }
}

/// The shadow cache (src/render/shadow_cache.rs): a renderer kept over a
/// sequence renders a layer again only when its light or a caster in its
/// volume changed, and every frame equals the frame a fresh renderer (which
/// renders every layer) gives for the same state, bit for bit.
#[test]
fn cached_shadow_layers_give_the_frames_of_a_fresh_render() {
    let Some(engine) = gpu() else {
        return;
    };
    let ctx = &engine.ctx;
    let mut s = scene(spot());
    s.lights.push(point());
    let opts = options(ShadowMode::Pcf);
    let rest: Vec<glam::Mat4> = s.instances.iter().map(|i| i.transform).collect();
    let moved = |dx: f32| {
        let mut t = rest.clone();
        t[1] = glam::Mat4::from_translation(Vec3::new(dx, 0.0, 0.0)) * t[1];
        t
    };
    let mut far_camera = camera();
    far_camera.eye += Vec3::new(0.5, 0.5, 0.0);
    // (what, transforms, camera, layers rendered: Some(n) exactly, None: 1..7)
    let frames = [
        ("first frame", rest.clone(), camera(), Some(7)),
        ("nothing changed", rest.clone(), camera(), Some(0)),
        ("the box moved", moved(0.3), camera(), None),
        ("nothing changed again", moved(0.3), camera(), Some(0)),
        ("the camera moved", moved(0.3), far_camera, Some(0)),
        ("the box moved back", rest.clone(), far_camera, None),
    ];
    let mut kept = Renderer::new(ctx, &s, &opts).unwrap();
    let mut prev = rest.clone();
    for (what, transforms, cam, expect) in frames {
        let motion = fxgraph::render::FrameMotion {
            transforms: transforms.clone(),
            prev_transforms: prev.clone(),
            ..Default::default()
        };
        let (out, stats) = kept
            .render_frame(ctx, &cam, &motion, W, H, Technique::Deferred, None)
            .unwrap();
        let cached = read_rgba_f32(ctx, &out.scene).unwrap();
        let mut fresh = Renderer::new(ctx, &s, &opts).unwrap();
        let (out, fresh_stats) = fresh
            .render_frame(ctx, &cam, &motion, W, H, Technique::Deferred, None)
            .unwrap();
        let reference = read_rgba_f32(ctx, &out.scene).unwrap();
        let worst = cached
            .iter()
            .zip(&reference)
            .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        eprintln!(
            "{what}: {} of {} layers rendered, largest difference from a fresh render {worst}",
            stats.shadow_layers_rendered, stats.shadow_layers
        );
        assert_eq!(stats.shadow_layers, 7, "{what}");
        assert_eq!(fresh_stats.shadow_layers_rendered, 7, "{what}");
        match expect {
            Some(n) => assert_eq!(stats.shadow_layers_rendered, n, "{what}"),
            None => assert!(
                (1..7).contains(&stats.shadow_layers_rendered),
                "{what}: {}",
                stats.shadow_layers_rendered
            ),
        }
        assert_eq!(worst, 0.0, "{what}");
        prev = transforms;
    }
    // without the cache every frame renders every layer
    let mut uncached = Renderer::new(
        ctx,
        &s,
        &RendererOptions {
            shadow_cache: false,
            ..opts.clone()
        },
    )
    .unwrap();
    for _ in 0..2 {
        let (_, stats) = uncached
            .render(ctx, &camera(), W, H, Technique::Deferred, None)
            .unwrap();
        assert_eq!(stats.shadow_layers_rendered, 7);
    }
}
