//! Tests of the deferred renderer (src/render, src/scene): scene loading, normal encodings,
//! agreement of the three techniques, light volumes, aux images, G-buffer files.
//!
//! GPU tests skip without an adapter unless FX_REQUIRE_GPU=1. glTF tests skip with a
//! message when ../shared/corpus is absent.

use crate::common;

use common::bench;
use common::gpu_context as gpu;
use common::renders::{rgb_psnr, save_rgb_review};
use common::scenes::{one_object, opaque_room};

use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::normal::{self, NormalEncoding};
use fxgraph::render::renderer::{GBUFFER_BYTES_COMPRESSED, GBUFFER_BYTES_TRADITIONAL};
use fxgraph::render::{RenderOutput, RenderStats, Renderer, RendererOptions, Technique};
use fxgraph::scene::builtin::{box_mesh, grid_plane, uv_sphere};
use fxgraph::scene::{Camera, Light, Material, Scene};
use glam::{Mat4, Vec3};
use std::path::PathBuf;

const W: u32 = 128;
const H: u32 = 96;

fn corpus() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/gltf");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipping: {} is absent", dir.display());
        None
    }
}

/// Renders and reads back the HDR scene image.
fn render(
    ctx: &GpuContext,
    r: &mut Renderer,
    camera: &Camera,
    technique: Technique,
) -> (Vec<[f32; 4]>, RenderOutput, RenderStats) {
    let (out, stats) = r
        .render(ctx, camera, W, H, technique, None)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    let pixels = read_rgba_f32(ctx, &out.scene).unwrap();
    (pixels, out, stats)
}

/// Writes `pixels` to tests/output/deferred_NAME.png for review.
fn save_review(name: &str, pixels: &[[f32; 4]]) {
    save_rgb_review(&format!("deferred_{name}"), (W, H), pixels);
}

/// PSNR (dB) over RGB clamped to [0, 1], and the largest absolute RGB difference.
fn compare(a: &[[f32; 4]], b: &[[f32; 4]]) -> (f64, f32) {
    let max = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0f32, f32::max);
    (rgb_psnr(a, b, true), max)
}

/// The built-in room rendered deferred from its default camera: (scene, output).
fn room_deferred(ctx: &GpuContext) -> (Scene, RenderOutput) {
    let scene = Scene::load("builtin:room").unwrap();
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    let camera = scene.default_camera();
    let (out, _) = r
        .render(ctx, &camera, W, H, Technique::Deferred, None)
        .unwrap();
    (scene, out)
}

fn mean_rgb(p: &[[f32; 4]]) -> f32 {
    p.iter().map(|v| v[0] + v[1] + v[2]).sum::<f32>() / (p.len() * 3) as f32
}

// ------------------------------------------------------------------ CPU tests

#[test]
fn normal_encodings_round_trip_over_the_sphere() {
    let oct = normal::measure_error(NormalEncoding::Octahedral, 10, 200_000);
    let sph = normal::measure_error(NormalEncoding::Spheremap, 10, 200_000);
    for e in [&oct, &sph] {
        eprintln!(
            "{:>10} 10-bit: max {:.4}° (front hemisphere {:.4}°), mean {:.4}°, worst at {:?}",
            e.encoding.name(),
            e.max_deg,
            e.max_front_deg,
            e.mean_deg,
            e.worst
        );
    }
    assert!(oct.max_deg < 0.25, "octahedral max error {}°", oct.max_deg);
    assert!(
        oct.mean_deg < 0.1,
        "octahedral mean error {}°",
        oct.mean_deg
    );
    assert!(
        sph.max_front_deg < 0.25,
        "spheremap front max error {}°",
        sph.max_front_deg
    );
    // the default is the encoding with the smaller worst case
    assert!(oct.max_deg < sph.max_deg);
    assert_eq!(NormalEncoding::default(), NormalEncoding::Octahedral);
}

#[test]
fn compressed_gbuffer_is_smaller_than_the_traditional_one() {
    assert_eq!(GBUFFER_BYTES_COMPRESSED, 16);
    assert_eq!(GBUFFER_BYTES_TRADITIONAL, 28);
}

#[test]
fn random_point_lights_are_deterministic_and_inside_the_bounds() {
    let mut a = Scene::load("builtin:bench").unwrap();
    let base = a.lights.len();
    let mut b = a.clone();
    a.add_random_point_lights(50, 42);
    b.add_random_point_lights(50, 42);
    assert_eq!(a.lights, b.lights);
    let mut c = Scene::load("builtin:bench").unwrap();
    c.add_random_point_lights(50, 43);
    assert_ne!(a.lights, c.lights);
    let bounds = a.bounds();
    let diag = bounds.diagonal();
    for l in &a.lights[base..] {
        assert!(l.position.cmpge(bounds.min).all() && l.position.cmple(bounds.max).all());
        let r = l.radius();
        assert!(r >= 0.039 * diag && r <= 0.101 * diag, "radius {r}");
    }
}

#[test]
fn camera_specs_parse() {
    let scene = Scene::load("builtin:room").unwrap();
    let c = Camera::parse_spec("eye=1,2,3;target=0,1,0;fov=60", &scene).unwrap();
    assert_eq!(c.eye, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(c.target, Vec3::new(0.0, 1.0, 0.0));
    assert!((c.fov_y.to_degrees() - 60.0).abs() < 1e-4);
    assert!(c.near > 0.0 && c.far > c.near);
    let named = Camera::parse_spec("room", &scene).unwrap();
    assert_eq!(named, scene.cameras[0].camera);
    assert_eq!(Camera::parse_spec("0", &scene).unwrap(), named);
    for bad in [
        "eye=1,2",
        "fov=500",
        "7",
        "nosuchcamera",
        "eye=0,4,11;zoom=2",
        "eye=a,b,c",
    ] {
        let e = Camera::parse_spec(bad, &scene).unwrap_err().to_string();
        assert!(
            e.contains(bad.split(';').next().unwrap()) || e.contains("camera"),
            "{bad}: {e}"
        );
    }
}

#[test]
fn scene_without_lights_gets_the_default_lights() {
    let mut s = Scene::load("builtin:room").unwrap();
    s.lights.clear();
    s.ensure_lights();
    assert_eq!(s.lights, Scene::default_lights());
    assert!(Scene::load("builtin:nothing").is_err());
}

#[test]
fn gltf_corpus_models_load() {
    let Some(dir) = corpus() else { return };
    for (file, min_tris) in [
        ("FlightHelmet/FlightHelmet.gltf", 90_000),
        ("CornellBox.glb", 10),
        ("assimp/BoxTextured-glTF/BoxTextured.gltf", 12),
        (
            "assimp/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
            1000,
        ),
    ] {
        let path = dir.join(file);
        let scene = Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{file}: {e}"));
        eprintln!(
            "{file}: {} triangles, {} instances, {} materials, {} textures, {} lights, {} cameras",
            scene.triangle_count(),
            scene.instances.len(),
            scene.materials.len(),
            scene.textures.len(),
            scene.lights.len(),
            scene.cameras.len()
        );
        assert!(scene.triangle_count() >= min_tris, "{file}");
        assert!(!scene.lights.is_empty(), "{file}: default lights expected");
        assert!(!scene.bounds().is_empty());
    }
}

#[test]
fn gltf_broken_files_give_errors_not_panics() {
    let Some(dir) = corpus() else { return };
    let mut files = Vec::new();
    let mut stack = vec![dir.join("broken")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "gltf" || x == "glb") {
                files.push(p);
            }
        }
    }
    files.sort();
    assert!(files.len() >= 15, "only {} broken files found", files.len());
    for f in files {
        let name = f.to_str().unwrap().to_string();
        let result = std::panic::catch_unwind(|| Scene::load(&name));
        let result = result.unwrap_or_else(|_| panic!("{name}: panicked"));
        match result {
            Ok(s) => panic!(
                "{name}: loaded ({} triangles) but should fail",
                s.triangle_count()
            ),
            Err(e) => {
                let msg = e.to_string();
                eprintln!("{msg}");
                assert!(
                    msg.contains(f.file_name().unwrap().to_str().unwrap()),
                    "{msg}"
                );
            }
        }
    }
}

// ------------------------------------------------------------------ GPU tests

/// The statistics of a deferred frame with light volumes (the path that
/// classifies every light on the CPU).
fn volume_stats(ctx: &GpuContext, scene: &Scene, camera: &Camera) -> RenderStats {
    let opts = RendererOptions {
        light_culling: fxgraph::render::renderer::LightCulling::Volumes,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, &opts).unwrap();
    render(ctx, &mut r, camera, Technique::Deferred).2
}

#[test]
fn techniques_render_the_same_opaque_room() {
    let Some(ctx) = gpu() else { return };
    let scene = opaque_room();
    let camera = scene.default_camera();
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let (deferred, _, _) = render(&ctx, &mut r, &camera, Technique::Deferred);
    save_review("room_deferred", &deferred);
    assert!(mean_rgb(&deferred) > 0.05, "image is too dark");
    // the volume classification is the volumes path's (cluster lists cull on
    // the GPU)
    let stats = volume_stats(&ctx, &scene, &camera);
    assert!(
        stats.volumes_outside + stats.volumes_inside > 10,
        "{stats:?}"
    );
    for t in [Technique::LightPrepass, Technique::Forward] {
        let (img, _, _) = render(&ctx, &mut r, &camera, t);
        save_review(&format!("room_{t}"), &img);
        let (psnr, max) = compare(&deferred, &img);
        eprintln!("deferred vs {t}: PSNR {psnr:.2} dB, max |diff| {max:.4}");
        assert!(psnr > 40.0, "deferred vs {t}: PSNR {psnr:.2} dB");
    }
}

/// Renders the opaque room from its default camera with every technique, without
/// and with the light `extra(camera)`: the image is the same, and the light is
/// among the visible ones (after culling) if and only if `visible`.
fn assert_light_changes_nothing(extra: impl Fn(&Camera) -> Light, visible: bool) {
    let Some(ctx) = gpu() else { return };
    let scene = opaque_room();
    let camera = scene.default_camera();
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    // with cluster lists the GPU counts the visible lights: read back
    let visible_lights = |r: &Renderer, s: &RenderStats| {
        r.read_visible_lights(&ctx)
            .unwrap()
            .unwrap_or(s.lights_visible)
    };
    for t in Technique::ALL {
        let (before, _, s0) = render(&ctx, &mut r, &camera, t);
        let v0 = visible_lights(&r, &s0);
        let mut lights = scene.lights.clone();
        lights.push(extra(&camera));
        r.set_lights(lights);
        let (after, _, s1) = render(&ctx, &mut r, &camera, t);
        let v1 = visible_lights(&r, &s1);
        r.set_lights(scene.lights.clone());
        let culled = if visible { "culled" } else { "not culled" };
        assert_eq!(v1, v0 + visible as usize, "{t}: {culled}");
        assert!(before == after, "{t}: the image changed");
    }
}

#[test]
fn light_outside_the_frustum_changes_nothing() {
    // behind the camera, radius 2: the sphere is entirely outside the frustum
    let behind = |camera: &Camera| {
        let eye = camera.eye + (camera.eye - camera.target).normalize() * 3.0;
        Light::point(eye, Vec3::ONE, 5.0, 2.0)
    };
    assert_light_changes_nothing(behind, false);
}

#[test]
fn light_volume_without_geometry_changes_nothing() {
    // in the air in front of the camera, 3 units from the nearest surface
    let in_the_air = |_: &Camera| Light::point(Vec3::new(0.0, 3.0, 6.0), Vec3::ONE, 5.0, 0.5);
    assert_light_changes_nothing(in_the_air, true);
}

#[test]
fn camera_inside_a_light_volume_still_lights() {
    let Some(ctx) = gpu() else { return };
    let mut scene = opaque_room();
    let camera =
        Camera::parse_spec("eye=0,2,4;target=0,1,-2;fov=70;near=0.05;far=40", &scene).unwrap();
    scene.lights = vec![
        Light::point(
            Vec3::new(0.0, 2.2, 3.0),
            Vec3::new(1.0, 0.9, 0.8),
            3.0 * std::f32::consts::PI,
            12.0,
        ),
        Light::spot(
            Vec3::new(0.3, 2.0, 4.2),
            Vec3::new(0.0, -0.3, -1.0),
            Vec3::new(0.6, 0.8, 1.0),
            3.0 * std::f32::consts::PI,
            12.0,
            0.3,
            0.6,
        ),
    ];
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let (deferred, _, _) = render(&ctx, &mut r, &camera, Technique::Deferred);
    let stats = volume_stats(&ctx, &scene, &camera);
    assert_eq!(stats.volumes_inside, 2, "{stats:?}");
    let (forward, _, _) = render(&ctx, &mut r, &camera, Technique::Forward);
    let (lpp, _, _) = render(&ctx, &mut r, &camera, Technique::LightPrepass);
    save_review("inside_deferred", &deferred);
    save_review("inside_forward", &forward);
    // Light::point fixes the radius where the light fades to ε, so the falloff, not
    // the intensity, sets how bright the room is.
    assert!(mean_rgb(&deferred) > 0.005, "dark: {}", mean_rgb(&deferred));
    for (name, img) in [("forward", &forward), ("light-prepass", &lpp)] {
        let (psnr, max) = compare(&deferred, img);
        eprintln!("camera inside volumes, deferred vs {name}: PSNR {psnr:.2} dB, max {max:.4}");
        assert!(psnr > 40.0, "deferred vs {name}: {psnr:.2} dB");
    }
}

#[test]
fn depth_aux_is_the_linear_depth_of_a_plane() {
    let Some(ctx) = gpu() else { return };
    let distance = 5.0;
    // the XZ plane rotated to face +Z, at z = -distance, much larger than the view
    let wall = Mat4::from_translation(Vec3::new(0.0, 0.0, -distance))
        * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(100.0));
    let grey = Material::phong("grey", Vec3::splat(0.5), 0.5, 32.0);
    let mut scene = one_object("plane test", "wall", grid_plane(4), grey, wall);
    scene.ensure_lights();
    let camera = Camera {
        eye: Vec3::ZERO,
        target: Vec3::NEG_Z,
        up: Vec3::Y,
        fov_y: 60f32.to_radians(),
        near: 0.1,
        far: 100.0,
    };
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    for t in Technique::ALL {
        let (_, out, _) = render(&ctx, &mut r, &camera, t);
        let depth = read_rgba_f32(&ctx, out.aux("depth").unwrap()).unwrap();
        let pos = read_rgba_f32(&ctx, out.aux("position").unwrap()).unwrap();
        let nrm = read_rgba_f32(&ctx, out.aux("normal").unwrap()).unwrap();
        let max_err = depth
            .iter()
            .map(|d| (d[0] - distance).abs())
            .fold(0.0f32, f32::max);
        eprintln!("{t}: max |linear depth - {distance}| = {max_err:e}");
        assert!(max_err < 2e-3, "{t}: depth error {max_err}");
        for (i, (p, n)) in pos.iter().zip(&nrm).enumerate() {
            // Rgba16Float: 1e-3 relative is about two f16 steps
            assert!(
                (p[2] + distance).abs() < distance * 1e-3,
                "{t}: position.z {} at {i}",
                p[2]
            );
            assert!(n[2] > 0.999 && n[3] == 1.0, "{t}: normal {n:?} at {i}");
        }
        // x, y from the inverse projection: the centre pixel is on the axis
        let c = pos[((H / 2) * W + W / 2) as usize];
        let half = (30f32.to_radians()).tan() * distance / H as f32;
        assert!(
            c[0].abs() < 2.0 * half * 1.5 && c[1].abs() < 2.0 * half,
            "{c:?}"
        );
        let camera_std = out.camera;
        assert_eq!((camera_std.near, camera_std.far), (0.1, 100.0));
    }
}

#[test]
fn aux_images_have_the_planned_names_and_formats() {
    let Some(ctx) = gpu() else { return };
    let (scene, out) = room_deferred(&ctx);
    let planned = fxgraph::render::published_aux(true);
    assert_eq!(out.aux.len(), planned.len());
    for ((name, tex), (pname, pformat)) in out.aux.iter().zip(&planned) {
        assert_eq!(name, pname);
        assert_eq!(
            tex.format(),
            fxgraph::gpu::executor::wgpu_format(*pformat),
            "{name}"
        );
        assert!(tex
            .usage()
            .contains(wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC));
        assert_eq!((tex.width(), tex.height()), (W, H));
    }
    assert_eq!(out.scene.format(), wgpu::TextureFormat::Rgba16Float);
    // material ids: the floor's id is 0, every drawn pixel has a valid id
    let material = read_rgba_f32(&ctx, out.aux("material").unwrap()).unwrap();
    let albedo = read_rgba_f32(&ctx, out.aux("albedo").unwrap()).unwrap();
    for (m, a) in material.iter().zip(&albedo) {
        if a[3] > 0.5 {
            assert!((m[0] * 255.0).round() < scene.materials.len() as f32);
        }
    }
}

#[test]
fn normal_encodings_agree_through_the_gpu() {
    let Some(ctx) = gpu() else { return };
    // A sphere filling the view: the G-buffer normal decoded by the resolve pass
    // against the same scene rendered with the other encoding and the forward
    // technique (which writes the same target from unencoded normals).
    let white = Material::phong("white", Vec3::ONE, 0.5, 32.0);
    let mut scene = one_object("sphere", "sphere", uv_sphere(64, 32), white, Mat4::IDENTITY);
    scene.ensure_lights();
    let camera = Camera::parse_spec("eye=0,0,2.2;target=0,0,0;fov=60", &scene).unwrap();
    let mut results = Vec::new();
    for enc in [NormalEncoding::Octahedral, NormalEncoding::Spheremap] {
        let mut r = Renderer::new(
            &ctx,
            &scene,
            &RendererOptions {
                normal_encoding: enc,
                ..Default::default()
            },
        )
        .unwrap();
        let (_, out, _) = render(&ctx, &mut r, &camera, Technique::Deferred);
        let n = read_rgba_f32(&ctx, out.aux("normal").unwrap()).unwrap();
        let g = read_rgba_f32(&ctx, &out.gbuffer.normal).unwrap();
        // CPU decode of the stored channels must equal the GPU decode
        let mut max_cpu_gpu = 0.0f64;
        for (stored, decoded) in g.iter().zip(&n) {
            if decoded[3] < 0.5 {
                continue;
            }
            let cpu = enc.decode(glam::Vec2::new(stored[0], stored[1]));
            let gpu = Vec3::new(decoded[0], decoded[1], decoded[2]);
            max_cpu_gpu = max_cpu_gpu.max(normal::angle_deg(cpu, gpu));
        }
        eprintln!("{}: CPU vs GPU decode max {max_cpu_gpu:.4}°", enc.name());
        assert!(max_cpu_gpu < 0.05, "{}: {max_cpu_gpu}°", enc.name());
        results.push(n);
    }
    let mut max = 0.0f64;
    for (a, b) in results[0].iter().zip(&results[1]) {
        if a[3] > 0.5 {
            max = max.max(normal::angle_deg(
                Vec3::new(a[0], a[1], a[2]),
                Vec3::new(b[0], b[1], b[2]),
            ));
        }
    }
    eprintln!("octahedral vs spheremap through the GPU: max {max:.4}°");
    assert!(max < 0.5, "{max}°");
}

#[test]
fn gbuffer_files_are_written() {
    let Some(ctx) = gpu() else { return };
    let (_scene, out) = room_deferred(&ctx);
    let dir = tempfile::tempdir().unwrap();
    let files = fxgraph::app::write_gbuffer(dir.path(), &out, &ctx, "builtin:room").unwrap();
    for name in [
        "depth.png",
        "depth.exr",
        "normal.png",
        "albedo.png",
        "material_id.png",
        "specular.png",
        "gbuffer_specular_model.png",
        "light_diffuse.exr",
        "light_specular.exr",
        "scene.exr",
    ] {
        let p = dir.path().join(name);
        assert!(files.contains(&p), "{name} not reported");
        let img = fxgraph::io::load_image(&p, &Default::default()).unwrap();
        assert_eq!((img.width, img.height), (W, H), "{name}");
    }
}

#[test]
fn default_light_makes_an_unlit_scene_visible() {
    let Some(ctx) = gpu() else { return };
    let grey = Material::phong("grey", Vec3::splat(0.7), 0.2, 16.0);
    let mut scene = one_object(
        "unlit box",
        "box",
        box_mesh(Vec3::ONE),
        grey,
        Mat4::IDENTITY,
    );
    assert!(scene.lights.is_empty());
    scene.ensure_lights();
    let camera = scene.default_camera();
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let (img, _, _) = render(&ctx, &mut r, &camera, Technique::Deferred);
    assert!(mean_rgb(&img) > 0.02, "black image: {}", mean_rgb(&img));
}

#[test]
fn gltf_scenes_render() {
    let Some(dir) = corpus() else { return };
    let Some(ctx) = gpu() else { return };
    for file in [
        "CornellBox.glb",
        "assimp/BoxTextured-glTF/BoxTextured.gltf",
        "FlightHelmet/FlightHelmet.gltf",
        "assimp/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
    ] {
        let scene = Scene::load(dir.join(file).to_str().unwrap()).unwrap();
        let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
        let (img, _, _) = render(&ctx, &mut r, &scene.default_camera(), Technique::Deferred);
        save_review(&file.replace('/', "_"), &img);
        let lit = img.iter().filter(|p| p[0] + p[1] + p[2] > 0.03).count();
        eprintln!(
            "{file}: mean {:.4}, {lit} lit pixels of {}",
            mean_rgb(&img),
            img.len()
        );
        assert!(
            lit * 20 > img.len(),
            "{file}: black image ({lit} lit pixels)"
        );
    }
}

/// The benchmark (not a test): `bash bench/renderer.sh`, or
/// `cargo test --release --test scene -- --ignored deferred::renderer_benchmark --nocapture`.
/// Environment: FX_BENCH_SIZE=WxH, FX_BENCH_LIGHTS=1,8,..., FX_BENCH_FRAMES=N,
/// FX_BENCH_WARMUP=N,
/// FX_BENCH_TECHNIQUES=deferred,light-prepass,forward, FX_BENCH_OUT=report.md.
#[test]
#[ignore]
fn renderer_benchmark() {
    use common::render_bench::{run_benchmark, BenchConfig};
    let Some(ctx) = gpu() else { return };
    let mut cfg = BenchConfig::default();
    if let Some((w, h)) = bench::size() {
        (cfg.width, cfg.height) = (w, h);
    }
    if let Some(s) = bench::setting::<String>("LIGHTS") {
        cfg.light_counts = s.split(',').map(|v| v.trim().parse().unwrap()).collect();
    }
    cfg.frames = bench::setting("FRAMES").unwrap_or(cfg.frames);
    cfg.warmup = bench::setting("WARMUP").unwrap_or(cfg.warmup);
    if let Some(s) = bench::setting::<String>("TECHNIQUES") {
        cfg.techniques = s.split(',').map(|v| v.parse().unwrap()).collect();
    }
    let report = run_benchmark(&ctx, &cfg, |row| {
        eprintln!(
            "  {:>13} {:>5} lights ({} visible): {:.1} ms",
            row.technique.to_string(),
            row.lights,
            row.visible,
            row.ms
        )
    })
    .unwrap();
    bench::publish(&report);
}
