//! Shadow maps (src/deferred/shadows.rs, shadow_pass.rs, shaders/shadow.wgsl) on
//! a box floating over a plane, no ambient light, white Lambertian material:
//! the shadow's position against a CPU ray-cast oracle, the shadowed radiance
//! near zero, the lit radiance at the analytic value E · albedo / π · cos θ, the
//! three techniques alike, `off` as the unshadowed image, the layer budget, and
//! the CLI's checks of the options.
//!
//! GPU tests skip without an adapter unless FX_REQUIRE_GPU=1.

mod common;

use common::brdf::illuminance;
use fxgraph::deferred::gbuffer::read_rgba_f32;
use fxgraph::deferred::renderer::DEFAULT_SHADOW_SIZE;
use fxgraph::deferred::{
    Camera, Instance, Light, Material, RenderStats, Renderer, RendererOptions, Scene,
    ShaderBinding, ShadowMode, Technique,
};
use glam::{Mat4, Vec3, Vec4};
use std::f32::consts::PI;
use std::process::Command;

const W: u32 = 160;
const H: u32 = 120;
/// Half the side of the ground plane (y = 0).
const GROUND: f32 = 8.0;
/// The floating box: centre and half size.
const BOX_CENTER: Vec3 = Vec3::new(0.0, 1.5, 0.0);
const BOX_HALF: Vec3 = Vec3::new(0.6, 0.5, 0.6);

fn scene(light: Light) -> Scene {
    let mut s = Scene {
        name: "box over a plane".into(),
        ..Default::default()
    };
    s.meshes.push(fxgraph::deferred::builtin::grid_plane(4));
    s.meshes
        .push(fxgraph::deferred::builtin::box_mesh(BOX_HALF * 2.0));
    s.materials.push(Material::new(
        "white lambert",
        ShaderBinding::new("standard").with("base_color", &[1.0, 1.0, 1.0, 1.0]),
        ShaderBinding::new("lambert"),
    ));
    s.instances.push(Instance {
        name: "ground".into(),
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::new(2.0 * GROUND, 1.0, 2.0 * GROUND)),
    });
    s.instances.push(Instance {
        name: "box".into(),
        mesh: 1,
        material: 0,
        transform: Mat4::from_translation(BOX_CENTER),
    });
    s.lights.push(light);
    s
}

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(1.0, 7.0, 7.5),
        target: Vec3::new(0.0, 0.0, 0.5),
        up: Vec3::Y,
        fov_y: 50f32.to_radians(),
        near: 0.1,
        far: 40.0,
    }
}

fn directional() -> Light {
    // π lux: a white Lambertian surface facing it has radiance 1
    Light::directional(Vec3::new(0.45, -1.0, 0.3), Vec3::ONE, PI)
}

fn spot() -> Light {
    Light::spot(
        Vec3::new(-1.0, 5.0, -0.5),
        Vec3::new(0.25, -1.0, 0.15),
        Vec3::ONE,
        60.0,
        14.0,
        0.55,
        0.75,
    )
}

fn point() -> Light {
    Light::point(Vec3::new(0.7, 3.6, -0.4), Vec3::ONE, 40.0, 14.0)
}

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

/// Writes `pixels` to tests/output/shadows_NAME.png for review.
fn save_review(name: &str, pixels: &[[f32; 4]]) {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/output");
    std::fs::create_dir_all(&dir).unwrap();
    let data: Vec<f32> = pixels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    fxgraph::io::save_image(
        &dir.join(format!("shadows_{}.png", name.replace(' ', "_"))),
        W,
        H,
        &fxgraph::io::Pixels::F32(data),
        &Default::default(),
    )
    .unwrap();
}

/// Entry and exit distances of the ray `o + t d` through the box, if it hits.
fn hit_box(o: Vec3, d: Vec3) -> Option<(f32, f32)> {
    let (lo, hi) = (BOX_CENTER - BOX_HALF, BOX_CENTER + BOX_HALF);
    let inv = d.recip();
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    (far >= near.max(0.0)).then_some((near, far))
}

/// What the oracle knows about one pixel of the ground.
#[derive(Clone, Copy)]
struct Ground {
    /// Radiance without shadows: E · cos θ / π (white Lambert).
    lit: f32,
    shadowed: bool,
}

/// Per pixel: the ground point under the pixel centre (None: the box or nothing)
/// with its analytic lit radiance and whether the box blocks the light.
fn oracle(light: &Light) -> Vec<Option<Ground>> {
    oracle_wrap(light, 0.0)
}

/// [`oracle`] for the user lighting shader `wrap_lambert` (docs/examples):
/// `E · max((n·l + w) / (1 + w)², 0) / π`; `w = 0` is Lambert.
fn oracle_wrap(light: &Light, wrap: f32) -> Vec<Option<Ground>> {
    let cam = camera();
    let inv = (cam.proj(W as f32 / H as f32) * cam.view()).inverse();
    let mut out = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let ndc_x = (x as f32 + 0.5) / W as f32 * 2.0 - 1.0;
            let ndc_y = 1.0 - (y as f32 + 0.5) / H as f32 * 2.0;
            let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let d = (far.truncate() / far.w - cam.eye).normalize();
            let t = -cam.eye.y / d.y;
            let p = cam.eye + d * t;
            let on_ground = d.y < 0.0 && p.x.abs() < GROUND && p.z.abs() < GROUND;
            let box_first = hit_box(cam.eye, d).is_some_and(|(near, _)| near < t);
            if !on_ground || box_first {
                out.push(None);
                continue;
            }
            let Some((l, e)) = illuminance(light, p, true) else {
                out.push(Some(Ground {
                    lit: 0.0,
                    shadowed: false,
                }));
                continue;
            };
            let lit = e.x * ((l.y + wrap) / ((1.0 + wrap) * (1.0 + wrap))).max(0.0) / PI;
            let reach = match light.kind {
                fxgraph::deferred::LightKind::Directional => f32::INFINITY,
                _ => (light.position - p).length(),
            };
            let shadowed = hit_box(p + l * 1e-4, l).is_some_and(|(near, _)| near < reach);
            out.push(Some(Ground { lit, shadowed }));
        }
    }
    out
}

/// Checks an image against the oracle on the ground pixels at least 2 px from
/// a shadow edge (and from the box and the ground's border): shadowed ones below
/// 0.1 × the lit value, lit ones within 3 % of it; at least 95 % must agree.
/// Returns (agreeing fraction, shadowed pixels, lit pixels).
fn check_against_oracle(name: &str, pixels: &[[f32; 4]], light: &Light) -> (f64, usize, usize) {
    check_against(name, pixels, &oracle(light))
}

fn check_against(name: &str, pixels: &[[f32; 4]], truth: &[Option<Ground>]) -> (f64, usize, usize) {
    save_review(name, pixels);
    let max_lit = truth.iter().flatten().map(|g| g.lit).fold(0.0f32, f32::max);
    let at = |x: i32, y: i32| -> Option<Ground> {
        if x < 0 || y < 0 || x >= W as i32 || y >= H as i32 {
            return None;
        }
        truth[(y as u32 * W + x as u32) as usize]
    };
    let (mut agree, mut total, mut shadow_px, mut lit_px) = (0usize, 0usize, 0usize, 0usize);
    let mut worst_lit = 0.0f32;
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let Some(g) = at(x, y) else { continue };
            // skip dim pixels (outside a spot's cone, past the light's reach)
            if g.lit < 0.05 * max_lit {
                continue;
            }
            let interior = (-2..=2).all(|dy| {
                (-2..=2).all(|dx| at(x + dx, y + dy).is_some_and(|n| n.shadowed == g.shadowed))
            });
            if !interior {
                continue;
            }
            total += 1;
            let v = pixels[(y as u32 * W + x as u32) as usize][1];
            let ok = if g.shadowed {
                shadow_px += 1;
                v < 0.1 * g.lit
            } else {
                lit_px += 1;
                worst_lit = worst_lit.max((v - g.lit).abs() / g.lit);
                (v - g.lit).abs() <= 0.03 * g.lit
            };
            if !ok && total - agree < 6 {
                eprintln!(
                    "{name}: ({x}, {y}) {} where the oracle says {} (lit value {})",
                    v,
                    if g.shadowed { "shadow" } else { "lit" },
                    g.lit
                );
            }
            agree += usize::from(ok);
        }
    }
    let fraction = agree as f64 / total.max(1) as f64;
    eprintln!(
        "{name}: {agree}/{total} pixels agree ({:.2} %), {shadow_px} shadowed, {lit_px} lit, worst lit error {:.2} %",
        fraction * 100.0,
        worst_lit * 100.0
    );
    assert!(
        shadow_px >= 100 && lit_px >= 300,
        "{name}: too few pixels to judge"
    );
    assert!(
        fraction >= 0.95,
        "{name}: only {:.2} % agree",
        fraction * 100.0
    );
    (fraction, shadow_px, lit_px)
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

#[test]
fn spot_light_shadow_matches_the_ray_cast_oracle() {
    if gpu().is_none() {
        return;
    }
    let light = spot();
    let (pixels, stats) = render(
        &scene(light.clone()),
        &options(ShadowMode::Pcf),
        Technique::Deferred,
    );
    assert_eq!(stats.shadow_layers, 1);
    check_against_oracle("spot", &pixels, &light);
}

#[test]
fn point_light_shadow_matches_the_ray_cast_oracle() {
    if gpu().is_none() {
        return;
    }
    let light = point();
    let (pixels, stats) = render(
        &scene(light.clone()),
        &options(ShadowMode::Pcf),
        Technique::Deferred,
    );
    assert_eq!(stats.shadow_layers, 6, "six cube faces");
    check_against_oracle("point", &pixels, &light);
}

/// PSNR (dB) over RGB clamped to [0, 1].
fn psnr(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let mut mse = 0.0f64;
    for (p, q) in a.iter().zip(b) {
        for c in 0..3 {
            let d = p[c].clamp(0.0, 1.0) - q[c].clamp(0.0, 1.0);
            mse += f64::from(d * d);
        }
    }
    mse /= (a.len() * 3) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (1.0 / mse).log10()
    }
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
            let db = psnr(&reference, &pixels);
            eprintln!("{name}: deferred vs {t}: {db:.1} dB");
            assert!(db >= 40.0, "{name}: deferred vs {t}: {db:.1} dB");
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
    let file = fxgraph::deferred::material::script::load_materials(
        "wrapped.fx",
        text,
        Some(dir.path()),
        0,
    )
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
/// `cargo test --test shadows -- --ignored shadow_benchmark --nocapture`.
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
    use fxgraph::deferred::renderer::LightCulling;
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
