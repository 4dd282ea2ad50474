//! The compute light pass (src/render/light_compute.rs) against the fragment
//! light pass it replaces: the same scene, camera and technique rendered with
//! `RendererOptions::compute_lighting` on and off must give the same image
//! (PSNR ≥ 50 dB over RGB clamped to [0, 1]) on the built-in room, the corpus
//! Cornell box and FlightHelmet lit by an HDR environment; and the three
//! techniques still agree with it (≥ 40 dB against deferred) on the room and the
//! Cornell box with 1,024 lights. (The animated skinned model's agreement is
//! tests/gpu_skinning.rs, which renders with the defaults, the compute pass.)

use crate::common;

use common::ibl::corpus;
use common::renders::{rgb_psnr, save_rgb_review};
use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{FrameMotion, Renderer, RendererOptions, Technique};
use fxgraph::scene::{Environment, EnvironmentSource, Scene};

const SIZE: (u32, u32) = (160, 120);

fn image(ctx: &GpuContext, scene: &Scene, technique: Technique, compute: bool) -> Vec<[f32; 4]> {
    let opts = RendererOptions {
        compute_lighting: compute,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, scene, &opts).unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let (out, _) = r
        .render(
            ctx,
            &scene.default_camera(),
            SIZE.0,
            SIZE.1,
            technique,
            None,
        )
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    read_rgba_f32(ctx, &out.scene).unwrap()
}

fn mean(p: &[[f32; 4]]) -> f64 {
    p.iter().map(|v| f64::from(v[0] + v[1] + v[2])).sum::<f64>() / (p.len() * 3) as f64
}

fn cornell_box() -> Scene {
    Scene::load(corpus("gltf/CornellBox.glb").to_str().unwrap()).unwrap()
}

/// Compute against fragment lighting in deferred shading and the light
/// pre-pass.
fn compute_matches_fragment(ctx: &GpuContext, scene: &Scene, what: &str) {
    for technique in [Technique::Deferred, Technique::LightPrepass] {
        let fragment = image(ctx, scene, technique, false);
        let compute = image(ctx, scene, technique, true);
        assert!(mean(&fragment) > 0.003, "{what} {technique}: dark image");
        let db = rgb_psnr(&fragment, &compute, true);
        eprintln!(
            "{what}, {technique}: compute vs fragment lighting {db:.1} dB (identical: {})",
            fragment == compute
        );
        if db < 50.0 {
            save_rgb_review(&format!("compute_{what}_{technique}"), SIZE, &compute);
            save_rgb_review(&format!("fragment_{what}_{technique}"), SIZE, &fragment);
        }
        assert!(db >= 50.0, "{what} {technique}: {db:.1} dB < 50 dB");
    }
}

#[test]
fn compute_lighting_matches_the_fragment_pass() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    compute_matches_fragment(ctx, &Scene::load("builtin:room").unwrap(), "room");
    compute_matches_fragment(ctx, &cornell_box(), "cornell box");
    let mut helmet = Scene::load(
        corpus("gltf/FlightHelmet/FlightHelmet.gltf")
            .to_str()
            .unwrap(),
    )
    .unwrap();
    helmet.set_environment(Some(Environment::new(EnvironmentSource::File(corpus(
        "hdri/city.exr",
    )))));
    compute_matches_fragment(ctx, &helmet, "flight helmet with city.exr");
}

/// The AUX resolve's compute dispatch (`fx_cs_aux_a`) against its fragment
/// pass: AUX.depth, normal, position and motion (the camera moved since the
/// previous frame) of the room, the same values; they are the same maths, and
/// the float conversions of a store and of a render target agree (measured:
/// identical on lavapipe; the limit allows 1e-6 relative).
#[test]
fn the_aux_resolve_in_compute_matches_the_fragment_pass() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let scene = Scene::load("builtin:room").unwrap();
    let camera = scene.default_camera();
    let mut before = camera;
    before.eye += glam::Vec3::new(0.2, 0.05, -0.1);
    let motion = FrameMotion {
        prev_camera: Some(before),
        ..Default::default()
    };
    let names = ["depth", "normal", "position", "motion"];
    let mut got = Vec::new();
    for compute in [false, true] {
        let opts = RendererOptions {
            compute_lighting: compute,
            ..Default::default()
        };
        let mut r = Renderer::new(ctx, &scene, &opts).unwrap();
        assert_eq!(r.resolves_aux_in_compute(), compute, "the path asked for");
        let (out, _) = r
            .render_frame(
                ctx,
                &camera,
                &motion,
                SIZE.0,
                SIZE.1,
                Technique::Deferred,
                None,
            )
            .unwrap();
        let images: Vec<Vec<[f32; 4]>> = names
            .iter()
            .map(|n| read_rgba_f32(ctx, out.aux(n).unwrap()).unwrap())
            .collect();
        got.push(images);
    }
    for (i, name) in names.iter().enumerate() {
        let (fragment, compute) = (&got[0][i], &got[1][i]);
        let moving = fragment
            .iter()
            .filter(|v| v[0].abs() + v[1].abs() > 0.01)
            .count();
        if *name == "motion" {
            assert!(
                moving > fragment.len() / 2,
                "the camera moved: {moving} moving pixels"
            );
        }
        let worst = fragment
            .iter()
            .zip(compute)
            .flat_map(|(a, b)| {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| (x - y).abs() / x.abs().max(1.0))
            })
            .fold(0.0f32, f32::max);
        eprintln!("AUX.{name}: compute vs fragment, largest relative difference {worst:e}");
        assert!(worst <= 1e-6, "AUX.{name}: {worst:e}");
    }
}

/// The AUX resolve's second half in compute (`fx_cs_aux_b`) against its
/// fragment pass: AUX.albedo, material and specular of the room. The 8-bit
/// images may differ by 1 LSB per channel (albedo is sRGB-encoded by the
/// shader into its raw twin rather than by the render target, and a store
/// and a render target may round an 8-bit value differently); AUX.specular
/// (R16Float) must be bit-identical. Measured on lavapipe: identical bytes.
/// AUX.albedo stays an `Rgba8UnormSrgb` texture on both paths, so its readers
/// see the same image.
#[test]
fn the_aux_albedo_material_specular_in_compute_match_the_fragment_pass() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let scene = Scene::load("builtin:room").unwrap();
    let camera = scene.default_camera();
    let names = ["albedo", "material", "specular"];
    let mut got = Vec::new();
    for compute in [false, true] {
        let opts = RendererOptions {
            compute_lighting: compute,
            ..Default::default()
        };
        let mut r = Renderer::new(ctx, &scene, &opts).unwrap();
        assert_eq!(
            r.resolves_aux_albedo_in_compute(),
            compute,
            "the path asked for"
        );
        let (out, _) = r
            .render(ctx, &camera, SIZE.0, SIZE.1, Technique::Deferred, None)
            .unwrap();
        let albedo = out.aux("albedo").unwrap();
        assert_eq!(albedo.format(), wgpu::TextureFormat::Rgba8UnormSrgb);
        let images: Vec<Vec<u8>> = names
            .iter()
            .map(|n| ctx.read_texture(out.aux(n).unwrap()).unwrap())
            .collect();
        got.push(images);
    }
    for (i, name) in names.iter().enumerate() {
        let (fragment, compute) = (&got[0][i], &got[1][i]);
        assert_eq!(fragment.len(), compute.len(), "AUX.{name}: size");
        assert!(
            fragment.iter().any(|&b| b != 0),
            "AUX.{name}: the room draws something"
        );
        let (worst, differing) = if *name == "specular" {
            let half = |b: &[u8]| -> Vec<u16> {
                b.chunks_exact(2)
                    .map(|c| u16::from_le_bytes([c[0], c[1]]))
                    .collect()
            };
            let (a, b) = (half(fragment), half(compute));
            let n = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            (u32::from(n > 0), n)
        } else {
            let worst = fragment
                .iter()
                .zip(compute)
                .map(|(x, y)| u32::from(x.abs_diff(*y)))
                .max()
                .unwrap_or(0);
            let n = fragment.iter().zip(compute).filter(|(x, y)| x != y).count();
            (worst, n)
        };
        eprintln!("AUX.{name}: compute vs fragment, {differing} values differ, largest {worst}");
        let limit = if *name == "specular" { 0 } else { 1 };
        assert!(worst <= limit, "AUX.{name}: {differing} values differ");
    }
}

/// The three techniques agree (≥ 40 dB against deferred) with the compute light
/// pass on the room and on the Cornell box lit by 1,024 random point lights.
#[test]
fn the_three_techniques_agree_with_compute_lighting() {
    let Some(gpu) = common::gpu_context() else {
        return;
    };
    let ctx = &*gpu;
    let mut many = cornell_box();
    many.add_random_point_lights(1024, 3);
    for (what, scene) in [
        ("room", Scene::load("builtin:room").unwrap()),
        ("cornell box, 1,024 lights", many),
    ] {
        let reference = image(ctx, &scene, Technique::Deferred, true);
        for technique in [Technique::LightPrepass, Technique::Forward] {
            let img = image(ctx, &scene, technique, true);
            let db = rgb_psnr(&reference, &img, true);
            eprintln!("{what}: {technique} against deferred {db:.1} dB");
            assert!(db >= 40.0, "{what} {technique}: {db:.1} dB < 40 dB");
        }
    }
}
