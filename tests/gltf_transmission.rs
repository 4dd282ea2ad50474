//! `KHR_materials_transmission` (thin-walled) against the extension's formula
//! computed on the CPU (tests/common/layers.rs): spheres in a constant and in a
//! known environment (the environment is what a thin wall transmits: no
//! screen-space refraction), a light behind a thin square, metals that transmit
//! nothing, and the extension read from glTF.

use crate::common;

use common::gltf_gen::{self, SpheresGltf};
use common::ibl::{self, interior_pixels, SPHERE_PX};
use common::layers::{self, Layered, Spread};
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::environment::Equirect;
use fxgraph::scene::{Environment, EnvironmentSource, Light, Scene};
use glam::Vec3;
use serde_json::json;

const GLASS: Vec3 = Vec3::new(0.9, 0.75, 0.3);

fn glass(transmission: f32, roughness: f32) -> Layered {
    Layered {
        base: GLASS,
        metallic: 0.0,
        roughness,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
        transmission,
    }
}

/// Spheres of yellow glass in a uniform environment of radiance 1: every 4th
/// interior pixel against the extension's BRDF + BTDF integrated over the map's
/// texels on the CPU (the transmitted albedo of a constant environment is
/// (1 − F0)·A of the split sum); a smooth wall against the Fresnel split
/// F + base·(1 − F). Mean relative error within 2 %, largest within 6 %, in
/// every technique.
#[test]
fn transmission_in_a_constant_environment_matches_the_extension() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let env = Environment::new(EnvironmentSource::Uniform(Vec3::ONE));
    let t = ibl::texels(&Equirect::from_fn(256, |_| Vec3::ONE));
    let (_, o) = ibl::sphere_camera();
    let pixels = interior_pixels(&o, 4);
    for m in [
        glass(1.0, 0.3),
        glass(1.0, 0.6),
        glass(0.5, 0.6),
        glass(1.0, 0.0),
    ] {
        let want: Vec<(u32, u32, Vec3)> = pixels
            .iter()
            .map(|&(x, y, n, v)| {
                if m.roughness == 0.0 {
                    // a mirror-smooth wall (a delta lobe the texels cannot
                    // integrate): it reflects F = Schlick(0.04, n.v) of the
                    // light and transmits the rest, tinted
                    let f = 0.04 + 0.96 * (1.0 - n.dot(v)).powi(5);
                    (x, y, Vec3::splat(f) + m.base * (1.0 - f))
                } else {
                    (x, y, layers::environment_radiance(&t, &m, n, v))
                }
            })
            .collect();
        let what = format!(
            "transmission {} (roughness {}) in a uniform environment",
            m.transmission, m.roughness
        );
        let scene = layers::sphere(&m, vec![], Some(env.clone()));
        layers::check_techniques(ctx, &what, &scene, &want, Spread::Largest, (0.02, 0.06));
    }
}

/// A smooth environment that differs front to back and left to right (written as
/// an EXR and loaded as a user's file): what the sphere shows is the light from
/// behind it, tinted by the base colour and blurred by its roughness. Every 4th
/// interior pixel against the CPU integral over the map's texels: mean relative
/// error within 5 % (measured 2.1 % at roughness 0.3, 3.8 % at 0.6; the largest
/// errors, 10 % and 30 %, are grazing pixels: the split sum's assumption n = v,
/// as for reflection).
#[test]
fn transmission_shows_the_environment_behind() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let dir = tempfile::tempdir().unwrap();
    let radiance = |d: Vec3| {
        Vec3::new(0.6 + 0.5 * d.z, 0.6 - 0.5 * d.z, 0.6 + 0.4 * d.x) + Vec3::splat(0.2 * d.y)
    };
    let map = Equirect::from_fn(256, radiance);
    let file = dir.path().join("front_back.exr");
    let px: Vec<f32> = map
        .texels
        .iter()
        .flat_map(|c| [c.x, c.y, c.z, 1.0])
        .collect();
    fxgraph::io::save_image(
        &file,
        map.width,
        map.height,
        &fxgraph::io::Pixels::F32(px),
        &Default::default(),
    )
    .unwrap();
    let env = Environment::new(EnvironmentSource::File(file));
    let t = ibl::texels(&map);
    let (_, o) = ibl::sphere_camera();
    let pixels = interior_pixels(&o, 4);
    for m in [glass(1.0, 0.3), glass(1.0, 0.6)] {
        let want: Vec<(u32, u32, Vec3)> = pixels
            .iter()
            .map(|&(x, y, n, v)| (x, y, layers::environment_radiance(&t, &m, n, v)))
            .collect();
        let px = layers::render(
            ctx,
            &layers::sphere(&m, vec![], Some(env.clone())),
            Technique::Deferred,
        );
        let (mean, worst) = layers::relative_errors(&px, &want);
        // the centre pixel (n = v = +Z) sees mostly -Z: red low, green high
        let c = px[((SPHERE_PX / 2) * SPHERE_PX + SPHERE_PX / 2) as usize];
        eprintln!(
            "transmission 1 (roughness {}) in the front/back map: mean {:.2} %, largest {:.2} % over {} pixels; centre {:.3} {:.3} {:.3}",
            m.roughness,
            mean * 100.0,
            worst * 100.0,
            want.len(),
            c[0],
            c[1],
            c[2]
        );
        assert!(mean <= 0.05, "mean {mean}");
        assert!(
            c[1] > 2.0 * c[0],
            "the light behind (-Z: green) must dominate: {c:?}"
        );
    }
}

/// A thin square of glass (transmission 0.5, roughness 0.4) between the eye and
/// a directional light behind it, plus a light in front: every 3rd pixel of the
/// square against the extension's BTDF for the light behind and the glTF BRDF
/// with its diffuse part × (1 − transmission) for the light in front. Mean
/// relative error within 1 %, 99th percentile within 3 %, in every technique.
#[test]
fn a_light_behind_a_thin_wall_shines_through() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let lights = vec![
        // travelling towards the eye, from behind the square
        Light::directional(Vec3::new(0.15, -0.1, 1.0), Vec3::new(1.0, 0.9, 0.8), 4.0),
        Light::directional(Vec3::new(-0.4, -0.3, -1.0), Vec3::ONE, 1.0),
    ];
    let m = glass(0.5, 0.4);
    let (_, o) = ibl::sphere_camera();
    let want: Vec<(u32, u32, Vec3)> = layers::square_pixels(&o, 3)
        .into_iter()
        .map(|(x, y, p, n, v)| (x, y, layers::punctual_radiance(&m, p, n, v, &lights)))
        .collect();
    // the light behind alone gives something: the test sees the transmission
    let behind: f32 = layers::square_pixels(&o, 3)
        .iter()
        .map(|&(_, _, p, n, v)| layers::punctual_radiance(&m, p, n, v, &lights[..1]).y)
        .fold(0.0, f32::max);
    assert!(behind > 0.3, "the light behind transmits {behind} at most");
    let what = format!("thin square, light behind (largest transmitted {behind:.3})");
    let scene = layers::square(&m, lights, None);
    layers::check_techniques(
        ctx,
        &what,
        &scene,
        &want,
        Spread::Percentile99,
        (0.01, 0.03),
    );
}

/// Metals absorb what enters them (the extension's "transparent metals"): a
/// metal sphere with transmission 1 renders exactly as with 0 in every
/// technique (a surface without a diffuse colour is not layered).
#[test]
fn metals_transmit_nothing() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let env = Some(Environment::new(EnvironmentSource::Studio));
    let lights = vec![Light::directional(
        Vec3::new(0.5, -0.4, -0.8),
        Vec3::ONE,
        2.0,
    )];
    let metal = |t: f32| Layered {
        base: Vec3::new(0.95, 0.64, 0.54),
        metallic: 1.0,
        roughness: 0.4,
        clearcoat: 0.0,
        clearcoat_roughness: 0.0,
        transmission: t,
    };
    for technique in Technique::ALL {
        let opaque = layers::render(
            ctx,
            &layers::sphere(&metal(0.0), lights.clone(), env.clone()),
            technique,
        );
        let clear = layers::render(
            ctx,
            &layers::sphere(&metal(1.0), lights.clone(), env.clone()),
            technique,
        );
        let differ = opaque.iter().zip(&clear).filter(|(a, b)| a != b).count();
        eprintln!("metal with transmission 1 against 0, {technique}: {differ} pixels differ");
        assert_eq!(differ, 0, "{technique}");
    }
}

/// transmissionFactor and transmissionTexture reach the standard surface and
/// render in every technique; a factor outside [0, 1], a bad texCoord or an
/// extension that is not an object is refused, naming the material or the path.
#[test]
fn transmission_is_read_from_gltf() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = gltf_gen::spheres_gltf_json(&SpheresGltf {
        textured: true,
        ..Default::default()
    });
    doc["materials"][1]["extensions"] = json!({"KHR_materials_transmission": {
        "transmissionFactor": 0.9,
        "transmissionTexture": {"index": 1, "texCoord": 1}
    }});
    let path = gltf_gen::write_gltf(dir.path(), "glass.gltf", &doc);
    let scene = Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let m = &scene.materials[1];
    let param = |name: &str| layers::param(m, name);
    assert_eq!(param("transmission"), vec![0.9]);
    assert_eq!(param("transmission_map_uv_offset")[2], 1.0, "texCoord 1");
    assert!(m
        .surface
        .textures
        .iter()
        .any(|(n, _)| n == "transmission_map"));
    if let Some(engine) = common::engine() {
        let mut r = Renderer::new(&engine.ctx, &scene, &RendererOptions::default()).unwrap();
        let camera = scene.cameras[0].camera;
        for technique in Technique::ALL {
            r.render(&engine.ctx, &camera, 96, 48, technique, None)
                .unwrap_or_else(|e| panic!("{technique}: {e}"));
        }
    }
    for (ext, want) in [
        (
            json!({"transmissionFactor": -0.5}),
            "transmissionFactor -0.5 must be a number in [0, 1]",
        ),
        (
            json!({"transmissionFactor": 1, "transmissionTexture": {"index": 0, "texCoord": -1}}),
            "texCoord",
        ),
        // (checked with the file's other extension values, at its JSON path)
        (
            json!(3),
            "/materials/1/extensions/KHR_materials_transmission must be an object",
        ),
    ] {
        let mut bad = doc.clone();
        bad["materials"][1]["extensions"]["KHR_materials_transmission"] = ext;
        let path = gltf_gen::write_gltf(dir.path(), "bad.gltf", &bad);
        let e = Scene::load(path.to_str().unwrap()).unwrap_err().to_string();
        eprintln!("{e}");
        assert!(e.contains(want), "{e}");
        assert!(
            e.contains("smooth_dielectric") || want.starts_with('/'),
            "{e}"
        );
    }
}
