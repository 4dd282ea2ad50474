//! Image-based lighting in whole scenes: the three techniques agree with an
//! environment and its background, the room under a studio map has no NaN, a
//! transparent background keeps alpha 0, the
//! prefiltered maps are cached, a lighting shader's `environment` replaces the
//! engine's term, a sky's sun casts shadows, and bad environment inputs are
//! refused with clear messages (`fxrun`).

use crate::common;
use crate::common::shadow_scene;

use common::cli::{code, fxrun, stderr};
use common::ibl::{env_sphere, interior_pixels, sphere_camera, SPHERE_PX};
use common::renders::{rgb_psnr, save_rgb_review};
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::environment::Sky;
use fxgraph::scene::material_file::{apply_materials, load_materials};
use fxgraph::scene::{Background, Environment, EnvironmentSource, LightKind, Scene};
use glam::Vec3;

fn frame(
    ctx: &fxgraph::gpu::context::GpuContext,
    r: &mut Renderer,
    camera: &fxgraph::scene::Camera,
    (w, h): (u32, u32),
    technique: Technique,
) -> Vec<[f32; 4]> {
    let (out, _) = r
        .render(ctx, camera, w, h, technique, None)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    read_rgba_f32(ctx, &out.scene).unwrap()
}

#[test]
fn techniques_agree_with_an_environment_and_its_background() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let mut scene = common::scenes::opaque_room();
    scene.set_environment(Some(Environment::new(EnvironmentSource::File(
        common::ibl::corpus("hdri/city.exr"),
    ))));
    let camera = scene.default_camera();
    let size = (160, 90);
    for background in [
        Background::Color(Vec3::new(0.1, 0.2, 0.3)),
        Background::Environment { blur: 0.3 },
    ] {
        let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
        r.set_background(background);
        let images: Vec<Vec<[f32; 4]>> = Technique::ALL
            .iter()
            .map(|t| frame(ctx, &mut r, &camera, size, *t))
            .collect();
        for (t, img) in Technique::ALL.iter().zip(&images).skip(1) {
            let q = rgb_psnr(&images[0], img, true);
            eprintln!("room with city.exr, {background:?}: {t} against deferred: {q:.1} dB");
            if q < 40.0 {
                save_rgb_review(&format!("environment_{t}"), size, img);
                save_rgb_review("environment_deferred", size, &images[0]);
            }
            assert!(q >= 40.0, "{t}: {q:.1} dB < 40 dB");
        }
        // the environment changes the image: it is on
        let mut off = Renderer::new(
            ctx,
            &common::scenes::opaque_room(),
            &RendererOptions::default(),
        )
        .unwrap();
        let dark = frame(ctx, &mut off, &camera, size, Technique::Deferred);
        assert!(rgb_psnr(&images[0], &dark, true) < 30.0);
    }
}

/// The room under studio.exr, 480 × 270, each technique: every pixel finite.
/// A bright cell behind the camera, nearly along a wall pixel's view
/// direction, made v·h round above 1 there and Schlick's `pow(1 − v·h, 5)`
/// NaN: two NaN pixels, which the effect chain's blurs spread into black
/// squares (`fxrun --scene builtin:room --environment studio.exr`).
#[test]
fn the_room_under_a_studio_map_has_no_nan() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let mut scene = Scene::load("builtin:room").unwrap();
    scene.set_environment(Some(Environment::new(EnvironmentSource::File(
        common::ibl::corpus("hdri/studio.exr"),
    ))));
    let camera = scene.default_camera();
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    for technique in Technique::ALL {
        let img = frame(ctx, &mut r, &camera, (480, 270), technique);
        let bad: Vec<usize> = (0..img.len())
            .filter(|&i| img[i].iter().any(|c| !c.is_finite()))
            .collect();
        assert!(
            bad.is_empty(),
            "{technique}: {} pixels not finite, the first at {:?}",
            bad.len(),
            bad.first().map(|i| (i % 480, i / 480))
        );
    }
}

#[test]
fn a_transparent_background_keeps_alpha_zero() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let mut scene = Scene::load("builtin:room").unwrap();
    scene.set_environment(Some(Environment::new(EnvironmentSource::Studio)));
    let camera = scene.default_camera();
    let size = (96, 54);
    for technique in Technique::ALL {
        let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
        r.set_background(Background::Transparent);
        let (out, _) = r
            .render(ctx, &camera, size.0, size.1, technique, None)
            .unwrap();
        let img = read_rgba_f32(ctx, &out.scene).unwrap();
        let depth = read_rgba_f32(ctx, out.aux("depth").unwrap()).unwrap();
        let (mut sky, mut solid) = (0, 0);
        for (p, d) in img.iter().zip(&depth) {
            if d[0] >= camera.far * 0.999 {
                assert_eq!(
                    *p, [0.0; 4],
                    "{technique}: a background pixel is not transparent"
                );
                sky += 1;
            } else {
                assert!(p[3] > 0.0, "{technique}: geometry with alpha {}", p[3]);
                solid += 1;
            }
        }
        eprintln!("{technique}: {sky} transparent background pixels, {solid} of geometry");
        assert!(sky > 100 && solid > 1000);
    }
}

#[test]
fn prefiltered_maps_are_cached_by_content() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let sky = Environment::new(EnvironmentSource::Sky(Sky::default()));
    let mut r = Renderer::new(
        ctx,
        &env_sphere(Vec3::ONE, 0.0, 0.5, sky.clone()),
        &RendererOptions::default(),
    )
    .unwrap();
    let (ms, count) = r.environment_prefiltering();
    assert!(ms > 0.0 && count == 1);
    // the same map again (another intensity and rotation: shading settings)
    let mut brighter = sky.clone();
    brighter.intensity = 2.0;
    brighter.rotation = 45.0;
    r.set_environment(ctx, Some(&brighter)).unwrap();
    assert_eq!(r.environment_prefiltering(), (0.0, 1), "prefiltered again");
    let studio = Environment::new(EnvironmentSource::Studio);
    r.set_environment(ctx, Some(&studio)).unwrap();
    assert_eq!(r.environment_prefiltering().1, 2);
    r.set_environment(ctx, Some(&sky)).unwrap();
    assert_eq!(r.environment_prefiltering(), (0.0, 2));
    r.set_environment(ctx, None).unwrap();
    assert!(r.environment_shape().is_none());
}

const USER_LIGHTING: &str = r#"
struct LightingParams {
    level: f32, // @default(0.25) @range(0, 1) what the environment gives
}

fn lighting(in: LightingInput, params: LightingParams) -> LightingOutput {
    return LightingOutput(in.light * max(dot(in.normal, in.light_dir), 0.0) / FX_PI, vec3<f32>(0.0));
}

// the environment's radiance times `level`, as specular light (no diffuse)
fn environment(in: EnvironmentInput, params: LightingParams) -> LightingOutput {
    return LightingOutput(vec3<f32>(0.0), in.irradiance * params.level);
}
"#;

#[test]
fn a_lighting_shader_may_replace_the_environment_term() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("flat_env.wgsl"), USER_LIGHTING).unwrap();
    let text =
        "MATERIAL.flat = { SURFACE = SHADER.standard LIGHTING = SHADER.flat_env { level = 0.25 } }";
    let mut scene = env_sphere(
        Vec3::ONE,
        0.0,
        0.5,
        Environment::new(EnvironmentSource::Uniform(Vec3::splat(2.0))),
    );
    let file =
        load_materials("flat.fx", text, Some(dir.path()), 0).unwrap_or_else(|e| panic!("{e}"));
    apply_materials(&mut scene, file, &[("*".into(), "flat".into())]).unwrap();
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    let (camera, o) = sphere_camera();
    for technique in Technique::ALL {
        let px = frame(ctx, &mut r, &camera, (SPHERE_PX, SPHERE_PX), technique);
        for (x, y, _, _) in interior_pixels(&o, 7) {
            let p = px[(y * SPHERE_PX + x) as usize];
            for c in 0..3 {
                assert!(
                    (p[c] - 0.5).abs() < 2e-3,
                    "{technique}: {:?} at ({x}, {y}), expected 0.5",
                    p
                );
            }
        }
    }
    // a wrong signature is the user's error, at its place
    std::fs::write(
        dir.path().join("bad_env.wgsl"),
        "fn lighting(in: LightingInput) -> LightingOutput { return LightingOutput(vec3<f32>(0.0), vec3<f32>(0.0)); }\nfn environment(x: f32) -> f32 { return x; }\n",
    )
    .unwrap();
    let text = "MATERIAL.bad = { SURFACE = SHADER.standard LIGHTING = SHADER.bad_env }";
    let err = load_materials("bad.fx", text, Some(dir.path()), 0).expect_err("refused");
    assert!(
        err.contains("bad_env.wgsl:2:1: error: `environment` must be"),
        "{err}"
    );
}

#[test]
fn the_sky_sun_is_a_directional_light_that_casts_shadows() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    // the shadow test scene with the sky's sun straight overhead instead of its light
    let mut scene = shadow_scene::scene(shadow_scene::directional());
    scene.lights.clear();
    let sky = Sky {
        elevation: 90.0,
        ..Sky::default()
    };
    scene.set_environment(Some(Environment::new(EnvironmentSource::Sky(sky))));
    let sun: Vec<_> = scene
        .lights
        .iter()
        .filter(|l| l.kind == LightKind::Directional)
        .collect();
    assert_eq!(sun.len(), 1);
    assert!(sun[0].casts_shadows && sun[0].direction.y < -0.999);
    let camera = shadow_scene::camera();
    let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
    let (out, _) = r
        .render(
            ctx,
            &camera,
            shadow_scene::W,
            shadow_scene::H,
            Technique::Deferred,
            None,
        )
        .unwrap();
    let img = read_rgba_f32(ctx, &out.scene).unwrap();
    let position = read_rgba_f32(ctx, out.aux("position").unwrap()).unwrap();
    // ground points straight under the box against ground points far from it
    let view = camera.view();
    let world = |p: &[f32; 4]| view.inverse().transform_point3(Vec3::new(p[0], p[1], p[2]));
    let (mut under, mut open) = (Vec::new(), Vec::new());
    for (c, p) in img.iter().zip(&position) {
        if p[3] == 0.0 {
            continue;
        }
        let w = world(p);
        if w.y.abs() > 0.01 {
            continue;
        }
        let d = Vec3::new(w.x, 0.0, w.z)
            - Vec3::new(shadow_scene::BOX_CENTER.x, 0.0, shadow_scene::BOX_CENTER.z);
        if d.x.abs() < 0.4 && d.z.abs() < 0.4 {
            under.push(c[1]);
        } else if d.length() > 2.5 {
            open.push(c[1]);
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
    eprintln!(
        "sky sun overhead: ground under the box {:.3} ({} px), in the open {:.3} ({} px)",
        mean(&under),
        under.len(),
        mean(&open),
        open.len()
    );
    assert!(!under.is_empty() && !open.is_empty());
    // in the open the sun (about π) and the sky; under the box the sky only
    assert!(mean(&under) < 0.6 * mean(&open));
}

/// `fxrun --scene builtin:room --environment FILE`, tiny.
fn run_env(args: &[&str]) -> std::process::Output {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.png");
    let mut all = vec![
        "--scene",
        "builtin:room",
        "--size",
        "32x18",
        "-o",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    fxrun(&all)
}

#[test]
fn bad_environment_inputs_are_refused_with_clear_messages() {
    let dir = tempfile::tempdir().unwrap();
    let save = |name: &str, w: u32, h: u32, f: &dyn Fn(u32) -> f32| {
        let p = dir.path().join(name);
        let px: Vec<f32> = (0..w * h)
            .flat_map(|i| {
                let v = f(i);
                [v, v, v, 1.0]
            })
            .collect();
        fxgraph::io::save_image(&p, w, h, &fxgraph::io::Pixels::F32(px), &Default::default())
            .unwrap();
        p.to_str().unwrap().to_string()
    };
    let square = save("square.exr", 32, 32, &|_| 1.0);
    let one = save("one.exr", 1, 1, &|_| 1.0);
    // (fxgraph's own writer turns NaN into 0: write the float EXR directly)
    let nan = dir.path().join("nan.exr");
    exr::prelude::write_rgb_file(&nan, 64, 32, |x, y| {
        let v = match (x, y) {
            (5, 0) => f32::NAN,
            (6, 0) => f32::INFINITY,
            _ => 0.5,
        };
        (v, 0.5f32, 0.5f32)
    })
    .unwrap();
    let nan = nan.to_str().unwrap().to_string();
    let ldr = save("ldr.png", 64, 32, &|i| (i % 64) as f32 / 64.0);
    let missing = dir.path().join("missing.exr").to_str().unwrap().to_string();
    // (arguments, exit status, what stderr must say)
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (
            vec!["--environment", &square],
            1,
            "width = 2 × height); this image is 32x32",
        ),
        (vec!["--environment", &one], 1, "this image is 1x1"),
        (vec!["--environment", &missing], 2, "missing.exr"),
        (
            vec!["--environment", "builtin:moon"],
            1,
            "unknown built-in environment `builtin:moon`",
        ),
        (
            vec!["--environment", "uniform:-1"],
            1,
            "uniform:V or uniform:R,G,B",
        ),
        (
            vec!["--environment", "none", "--background", "environment"],
            1,
            "--background environment needs an environment",
        ),
        (vec!["--background", "sky"], 1, "--background sky: expected"),
        (
            vec!["--sun", "30,60"],
            1,
            "--sun and --turbidity set builtin:sky",
        ),
        (
            vec!["--environment", "builtin:sky", "--sun", "95,0"],
            1,
            "--sun: elevation 95",
        ),
        (
            vec!["--environment", "builtin:sky", "--turbidity", "40"],
            1,
            "--turbidity 40",
        ),
        (
            vec!["--environment-intensity", "-1"],
            1,
            "--environment-intensity -1",
        ),
        // accepted, with a note: NaN/Inf texels, an 8-bit map
        (
            vec!["--environment", &nan],
            0,
            "2 NaN or infinite sample(s) replaced by 0",
        ),
        (
            vec!["--environment", &ldr],
            0,
            "an 8-bit image, read as sRGB-encoded display values",
        ),
    ];
    for (args, status, says) in cases {
        let o = run_env(&args);
        let e = stderr(&o);
        assert_eq!(code(&o), status, "{args:?}: {e}");
        assert!(e.contains(says), "{args:?}: `{says}` not in: {e}");
        assert!(!e.contains("panicked"), "{args:?}: {e}");
    }
}
