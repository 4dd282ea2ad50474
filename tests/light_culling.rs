//! Light culling (src/render/clusters.rs and the light volumes): the clustered
//! lists and the volumes must give the image that shading every light at every
//! pixel gives, in the three techniques, with many lights, with the camera
//! inside light volumes, and with volumes cut by the near and far planes; and
//! the light edge cases (zero and negative intensity, spot cones of 0° and 90°,
//! a light inside an object, 10,000 lights, 16,384 lights binned on the GPU).
//! The GPU lists themselves are compared with the CPU reference in
//! src/render/cluster_gpu_tests.rs.

use crate::common;

use common::cli::{exits_with, fxrun_line};
use common::gpu_context;
use common::renders::rgb_psnr;

use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::renderer::LightCulling;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::{Camera, Light, Scene};
use glam::Vec3;

const W: u32 = 192;
const H: u32 = 128;

fn render(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    technique: Technique,
    culling: LightCulling,
) -> (Vec<[f32; 4]>, fxgraph::render::RenderStats) {
    render_sized(ctx, scene, camera, (technique, culling), (W, H))
}

/// [`render`] at `width`×`height`.
fn render_sized(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    (technique, culling): (Technique, LightCulling),
    (width, height): (u32, u32),
) -> (Vec<[f32; 4]>, fxgraph::render::RenderStats) {
    let mut r = Renderer::new(
        ctx,
        scene,
        &RendererOptions {
            light_culling: culling,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let (out, mut stats) = r
        .render(ctx, camera, width, height, technique, None)
        .unwrap_or_else(|e| panic!("{technique} {culling}: {e}"));
    // with cluster lists the GPU counts the visible lights: read back
    if let Some(n) = r.read_visible_lights(ctx).unwrap() {
        stats.lights_visible = n;
    }
    (read_rgba_f32(ctx, &out.scene).unwrap(), stats)
}

/// [`render`] with the deferred technique.
fn deferred(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    culling: LightCulling,
) -> (Vec<[f32; 4]>, fxgraph::render::RenderStats) {
    render(ctx, scene, camera, Technique::Deferred, culling)
}

fn mean(p: &[[f32; 4]]) -> f64 {
    p.iter().map(|v| f64::from(v[0] + v[1] + v[2])).sum::<f64>() / (p.len() * 3) as f64
}

/// The built-in room without its lights.
fn unlit_room() -> Scene {
    let mut scene = Scene::load("builtin:room").unwrap();
    scene.lights.clear();
    scene
}

/// The built-in room lit by `n` random point lights (the renderer benchmark's
/// sizes: 4–10 % of the scene diagonal) and nothing else.
fn room_with_lights(n: usize, seed: u64) -> Scene {
    let mut scene = unlit_room();
    scene.add_random_point_lights(n, seed);
    scene
}

/// Checks every technique × culling against the unculled reference.
fn agree(ctx: &GpuContext, scene: &Scene, camera: &Camera, what: &str) {
    for t in Technique::ALL {
        let (reference, _) = render(ctx, scene, camera, t, LightCulling::None);
        assert!(mean(&reference) > 0.003, "{what} {t}: dark reference");
        for culling in [LightCulling::Clustered, LightCulling::Volumes] {
            let (img, stats) = render(ctx, scene, camera, t, culling);
            let db = rgb_psnr(&reference, &img, false);
            eprintln!(
                "{what}, {t}, {culling} vs none: PSNR {db:.1} dB ({} cluster entries, max {} per cluster)",
                stats.cluster_entries, stats.cluster_max
            );
            assert!(db >= 50.0, "{what}: {t} {culling}: {db:.1} dB");
        }
    }
}

#[test]
fn many_lights_cull_without_changing_the_image() {
    let Some(engine) = common::engine() else {
        return;
    };
    let scene = room_with_lights(300, 7);
    agree(&engine.ctx, &scene, &scene.default_camera(), "300 lights");
}

/// The camera stands among the lights (inside several volumes), the near plane
/// cuts volumes in front of it and the far plane cuts the distant ones.
#[test]
fn camera_inside_volumes_and_clipping_planes_cull_exactly() {
    let Some(engine) = common::engine() else {
        return;
    };
    let mut scene = room_with_lights(200, 3);
    let camera =
        Camera::parse_spec("eye=0,1.5,2;target=0,1,-3;fov=75;near=0.3;far=6", &scene).unwrap();
    // big lights round the eye, one exactly at it
    for (i, p) in [
        Vec3::new(0.0, 1.5, 2.0),
        Vec3::new(0.4, 1.2, 1.8),
        Vec3::new(-0.5, 1.8, 2.3),
    ]
    .into_iter()
    .enumerate()
    {
        scene.lights.push(Light {
            name: format!("around the eye {i}"),
            ..Light::point(p, Vec3::new(1.0, 0.8, 0.6), 2.0, 4.0)
        });
    }
    scene.lights.push(Light::spot(
        Vec3::new(0.0, 2.0, 2.5),
        Vec3::new(0.0, -0.3, -1.0),
        Vec3::ONE,
        4.0,
        8.0,
        0.2,
        0.5,
    ));
    agree(
        &engine.ctx,
        &scene,
        &camera,
        "camera inside, clipped volumes",
    );
}

/// Lights of zero or negative intensity are ignored (the renderer logs a
/// warning once), and do not change the image.
#[test]
fn dark_lights_are_ignored() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = room_with_lights(20, 5);
    let camera = scene.default_camera();
    let (before, s0) = deferred(ctx, &scene, &camera, LightCulling::default());
    let mut dark = scene.clone();
    dark.lights
        .push(Light::point(Vec3::new(0.0, 1.0, 0.0), Vec3::ONE, 0.0, 3.0));
    let mut negative = Light::point(Vec3::new(0.5, 1.0, 0.0), Vec3::ONE, 1.0, 3.0);
    negative.intensity = -5.0;
    dark.lights.push(negative);
    let mut nan = Light::directional(Vec3::NEG_Y, Vec3::ONE, 1.0);
    nan.intensity = f32::NAN;
    dark.lights.push(nan);
    let (after, s1) = deferred(ctx, &dark, &camera, LightCulling::default());
    assert_eq!(s1.lights_visible, s0.lights_visible);
    assert_eq!(s1.lights_dark, 3);
    assert!(before == after, "dark lights changed the image");
}

/// Spot cones of 0° and 90° (half-angles), in every technique and culling: the
/// narrow one lights (almost) nothing, the wide one a hemisphere, and the
/// culled images equal the reference.
#[test]
fn extreme_spot_cones() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let mut scene = unlit_room();
    let spot = |outer: f32| {
        Light::spot(
            Vec3::new(0.0, 2.5, 0.0),
            Vec3::NEG_Y,
            Vec3::ONE,
            20.0,
            // the falloff is fixed by where it reaches 1/256 of the peak
            100.0,
            0.0,
            outer,
        )
    };
    let camera = scene.default_camera();
    // the room has emissive surfaces: measure the light added to them
    let (black, _) = deferred(ctx, &scene, &camera, LightCulling::None);
    scene.lights = vec![spot(0.0)];
    let (narrow, _) = deferred(ctx, &scene, &camera, LightCulling::None);
    scene.lights = vec![spot(std::f32::consts::FRAC_PI_2)];
    let (wide, _) = deferred(ctx, &scene, &camera, LightCulling::None);
    let (narrow, wide) = (mean(&narrow) - mean(&black), mean(&wide) - mean(&black));
    eprintln!("light added: spot 0°: {narrow:.6}; spot 90°: {wide:.6}");
    assert!(narrow < 0.01 * wide, "a 0° cone lit the room");
    assert!(wide > 0.01, "a 90° cone left the room dark");
    for outer in [0.0, std::f32::consts::FRAC_PI_2] {
        scene.lights = vec![spot(outer)];
        agree(ctx, &scene, &camera, &format!("spot {outer:.2} rad"));
    }
}

/// A point light inside an object (the room's centre, where its geometry is):
/// culled exactly, finite everywhere.
#[test]
fn light_inside_an_object() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let mut scene = unlit_room();
    let camera = scene.default_camera();
    let b = scene.bounds();
    let centre = (b.min + b.max) * 0.5;
    scene.lights.push(Light::point(centre, Vec3::ONE, 3.0, 2.0));
    let (img, _) = deferred(ctx, &scene, &camera, LightCulling::default());
    assert!(img.iter().all(|p| p.iter().all(|c| c.is_finite())));
    agree(ctx, &scene, &camera, "light inside an object");
}

/// 10,000 lights render without error and report the bytes of their lists.
#[test]
fn ten_thousand_lights() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = room_with_lights(10_000, 11);
    let camera = scene.default_camera();
    let (img, stats) = deferred(ctx, &scene, &camera, LightCulling::default());
    eprintln!(
        "10,000 lights: {} visible, {} cluster entries (max {} per cluster), {:.1} KiB of lists",
        stats.lights_visible,
        stats.cluster_entries,
        stats.cluster_max,
        stats.cluster_bytes as f64 / 1024.0
    );
    assert!(stats.lights_visible > 1000);
    assert!(stats.cluster_bytes > 0);
    assert!(mean(&img) > 0.01);
}

/// 16,384 lights binned on the GPU: the clustered image equals the one that
/// shades every light at every pixel (≥ 50 dB; the lists hold each pixel's
/// lights in the same order, so it is bit-identical in practice), and the
/// timed frame reads the GPU's entry count back. At 96×64: the reference loops
/// over every light at every pixel, 14 s at 192×128 on lavapipe; the lists
/// themselves are checked against the CPU reference at 1920×1080
/// (`render::cluster_gpu_tests::sixteen_thousand_lights_on_the_gpu`).
#[test]
fn sixteen_thousand_lights_clustered_on_the_gpu() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = room_with_lights(16_384, 5);
    let camera = scene.default_camera();
    let (w, h) = (96, 64);
    let (reference, _) = render_sized(
        ctx,
        &scene,
        &camera,
        (Technique::Deferred, LightCulling::None),
        (w, h),
    );
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    let timer = fxgraph::gpu::context::GpuTimer::new(ctx, 24);
    let (out, stats) = r
        .render(ctx, &camera, w, h, Technique::Deferred, timer.as_ref())
        .unwrap();
    // timed frames read the GPU's count back; so does the renderer when asked
    let visible = r.read_visible_lights(ctx).unwrap();
    assert!(timer.is_none() || visible == Some(stats.lights_visible));
    let img = read_rgba_f32(ctx, &out.scene).unwrap();
    let db = rgb_psnr(&reference, &img, false);
    let same = reference == img;
    eprintln!(
        "16,384 lights: {} visible, {} cluster entries (max {} per cluster), clustered vs none {db:.1} dB (identical: {same}), passes {:?}",
        stats.lights_visible, stats.cluster_entries, stats.cluster_max, stats.pass_ms
    );
    assert!(visible > Some(1000));
    assert!(mean(&img) > 0.01);
    assert!(db >= 50.0, "clustered vs none: {db:.1} dB");
    if timer.is_some() {
        assert!(stats.cluster_entries >= stats.lights_visible);
    }
}

/// A scene without geometry is an input error (exit 1) naming the file.
#[test]
fn a_scene_without_geometry_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.gltf");
    std::fs::write(
        &path,
        r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0}"#,
    )
    .unwrap();
    let o = fxrun_line("--scene {} -o {}", &[&path, &dir.path().join("out.png")]);
    exits_with(&o, 1, &["empty.gltf", "no triangles"]);
    assert!(!dir.path().join("out.png").exists());
}
