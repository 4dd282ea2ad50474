//! Fog in the lighting template (src/render/fog.rs): the same image as the
//! `fog` post effect with the same parameters, the three techniques agreeing,
//! height fog thicker low down, and bad settings rejected together.

use crate::common;

use common::cli::{exits, exits_with, fxrun_line};
use common::scenes::opaque_room;

use fxgraph::io::{load_image, Pixels};
use fxgraph::render::fog::Fog;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::Scene;
use glam::Vec3;
use std::path::Path;

fn floats(path: &Path) -> Vec<f32> {
    match load_image(path, &Default::default()).unwrap().pixels {
        Pixels::F32(v) => v,
        Pixels::U8(_) => panic!("{}: expected float pixels", path.display()),
    }
}

/// `--fog density=D` (template) equals the `fog` effect with `fog.density=D`
/// on the unfogged render: exponential fog of the view-axis depth, the
/// background included (both fog it at distance `far`). Both runs end with
/// `tonemap` (a run without effects would get the default chain).
#[test]
fn template_fog_equals_the_fog_effect() {
    if common::engine().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (
        dir.path().join("effect.exr"),
        dir.path().join("template.exr"),
    );
    // The same room, fogged by the effect and by the template.
    let room = "--scene builtin:room --size 160x96";
    let effect =
        format!("fog tonemap --set fog.density=0.15 --set fog.color=(0.6,0.5,0.4) {room} -o {{}}");
    exits(&fxrun_line(&effect, &[&a]), 0);
    let template = format!("tonemap --fog density=0.15 --fog color=0.6,0.5,0.4 {room} -o {{}}");
    exits(&fxrun_line(&template, &[&b]), 0);
    let (ea, eb) = (floats(&a), floats(&b));
    assert_eq!(ea.len(), eb.len());
    // Transparent surfaces differ: the template fogs them at their own depth,
    // the effect at the depth of the opaque surface behind (AUX.depth holds
    // opaque geometry only). The room's glass sphere and lamp cover < 3 %.
    let mut differ = 0usize;
    let mut worst = 0.0f32;
    for (p, q) in ea.chunks(4).zip(eb.chunks(4)) {
        // both went through an Rgba16Float scene texture: half-float rounding
        let e = (0..3)
            .map(|c| (p[c] - q[c]).abs() / p[c].abs().max(q[c].abs()).max(0.05))
            .fold(0.0f32, f32::max);
        if e > 4e-3 {
            differ += 1;
        }
        worst = worst.max(e);
    }
    let share = differ as f64 / (ea.len() / 4) as f64;
    eprintln!(
        "template fog vs fog effect: {:.2} % of pixels differ by > 0.4 % (worst {worst:.4})",
        share * 100.0
    );
    assert!(share < 0.03, "{:.2} % of pixels differ", share * 100.0);
    assert!(worst < 0.05, "worst relative difference {worst}");
    // and the fog is there: the fogged image is not the plain one
    let c = dir.path().join("plain.exr");
    exits(&fxrun_line(&format!("tonemap {room} -o {{}}"), &[&c]), 0);
    let plain = floats(&c);
    let changed = plain
        .chunks(4)
        .zip(eb.chunks(4))
        .filter(|(p, q)| (p[0] - q[0]).abs() > 0.01)
        .count();
    assert!(
        changed * 2 > plain.len() / 4,
        "fog changed only {changed} pixels"
    );
}

/// Renders one frame and reads back the scene and the AUX view-space position.
fn render(
    scene: &Scene,
    fog: Option<&Fog>,
    technique: Technique,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let engine = common::engine().unwrap();
    let ctx = &engine.ctx;
    let mut r = Renderer::new(ctx, scene, &RendererOptions::default()).unwrap();
    r.set_fog(fog.copied());
    let (out, _) = r
        .render(ctx, &scene.default_camera(), 160, 96, technique, None)
        .unwrap();
    let position = out.aux_map()["position"];
    (
        read_rgba_f32(ctx, &out.scene).unwrap(),
        read_rgba_f32(ctx, position).unwrap(),
    )
}

/// Height fog of the radial distance against a CPU oracle of the fog maths
/// (effects/fog.fx) at every pixel's view-space position, and the three
/// techniques agreeing.
#[test]
fn height_fog_matches_the_oracle_in_every_technique() {
    if common::engine().is_none() {
        return;
    }
    let scene = opaque_room();
    let fog = Fog::parse(&[
        "density=0.3".into(),
        "distance=radial".into(),
        "height_falloff=1.5".into(),
        "fog_height=0.5".into(),
        "color=0.6,0.5,0.4".into(),
    ])
    .unwrap();
    let camera = scene.default_camera();
    let up = camera.view().transform_vector3(Vec3::Y).normalize();
    let k = fog.height_falloff;
    let (plain, position) = render(&scene, None, Technique::Deferred);
    let mut first: Option<Vec<[f32; 4]>> = None;
    for t in Technique::ALL {
        let (fogged, _) = render(&scene, Some(&fog), t);
        let (mut checked, mut bad) = (0usize, 0usize);
        for ((p, q), pos) in plain.iter().zip(&fogged).zip(&position) {
            if pos[3] < 0.5 {
                continue; // background
            }
            // the channel where surface and fog differ most measures f best
            let c = (0..3)
                .max_by(|&a, &b| {
                    (p[a] - fog.color[a])
                        .abs()
                        .total_cmp(&(p[b] - fog.color[b]).abs())
                })
                .unwrap();
            let span = p[c] - fog.color[c];
            if span.abs() < 0.05 {
                continue;
            }
            let measured = (q[c] - fog.color[c]) / span;
            let v = Vec3::new(pos[0], pos[1], pos[2]);
            let x = k * v.dot(up);
            let mean = if x.abs() < 1e-3 {
                1.0 - x * (0.5 - x / 6.0)
            } else {
                (1.0 - (-x).exp()) / x
            };
            let d = v.length() * (-k * (camera.eye.y - fog.fog_height)).exp() * mean;
            let expected = fog.transmittance(d);
            checked += 1;
            if (measured - expected).abs() > 0.02 {
                bad += 1;
            }
        }
        eprintln!("{t}: {bad} of {checked} pixels off the oracle by > 0.02 in transmittance");
        assert!(checked > 5000, "{t}: only {checked} pixels checked");
        assert!(bad * 100 < checked, "{t}: {bad} of {checked} off");
        match &first {
            None => first = Some(fogged),
            Some(d) => {
                let mut mse = 0.0f64;
                for (p, q) in d.iter().zip(&fogged) {
                    for c in 0..3 {
                        mse += f64::from(p[c] - q[c]).powi(2);
                    }
                }
                let psnr = 10.0 * (1.0 / (mse / (fogged.len() * 3) as f64)).log10();
                eprintln!("height fog, deferred vs {t}: PSNR {psnr:.1} dB");
                assert!(psnr > 40.0, "deferred vs {t}: {psnr:.1} dB");
            }
        }
    }
}

#[test]
fn bad_fog_settings_are_rejected_together() {
    let o = fxrun_line(
        "--scene builtin:room --fog density=-1 --fog colour=1 -o /nonexistent/x.png",
        &[],
    );
    exits_with(&o, 1, &["density", "colour"]);
}

/// The default chain's fog is scaled to the scene: the Cornell box of the
/// corpus (modelled hundreds of units wide) keeps its colours instead of
/// vanishing in a uniform fog, as it did with a fixed density.
#[test]
fn default_chain_fog_is_scaled_to_the_scene() {
    if common::engine().is_none() {
        return;
    }
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/gltf/CornellBox.glb");
    if !scene.exists() {
        eprintln!("skipping: {} is absent", scene.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("box.png");
    exits(
        &fxrun_line("--scene {} --size 160x96 -o {}", &[&scene, &out]),
        0,
    );
    let img = load_image(&out, &Default::default()).unwrap();
    let Pixels::U8(px) = img.pixels else {
        panic!("expected 8-bit pixels")
    };
    // the red wall: some pixel much redder than green
    let reddest = px
        .chunks(4)
        .map(|p| i32::from(p[0]) - i32::from(p[1]))
        .max()
        .unwrap();
    let greenest = px
        .chunks(4)
        .map(|p| i32::from(p[1]) - i32::from(p[0]))
        .max()
        .unwrap();
    eprintln!("default chain on the Cornell box: red - green up to {reddest}, green - red up to {greenest}");
    assert!(reddest > 60 && greenest > 30, "the walls' colours are gone");
}
