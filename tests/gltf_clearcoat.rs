//! `KHR_materials_clearcoat` against the extension's formula computed on the CPU
//! (tests/common/layers.rs): a coated sphere under a directional light and under
//! a constant environment in all three techniques, a coat of strength 0 that
//! leaves the material exactly as it was, and the extension read from glTF.

use crate::common;

use common::brdf::{self, render_sphere_oracle, Model, Surface};
use common::gltf_gen::{self, SpheresGltf};
use common::ibl::{self, interior_pixels, SPHERE_PX};
use common::layers::{self, Layered, Spread};
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::environment::Equirect;
use fxgraph::scene::{Environment, EnvironmentSource, Light, Scene};
use glam::Vec3;
use serde_json::json;

const PAINT: Vec3 = Vec3::new(0.8, 0.25, 0.15);

fn coated(clearcoat: f32, clearcoat_roughness: f32) -> Layered {
    Layered {
        base: PAINT,
        metallic: 0.0,
        roughness: 0.6,
        clearcoat,
        clearcoat_roughness,
        transmission: 0.0,
    }
}

/// A coat over red paint, lit from the front left by a directional light and a
/// dim ambient light: every interior pixel against
/// `mix(material, D·V·(n·l)·E, clearcoat · Schlick(0.04, n·v))`, relative error
/// per channel (relative to max(reference, 0.02)): the mean within 1 %, the 99th
/// percentile within 3 % (deferred and the light pre-pass shade coated pixels
/// with the forward loop in their geometry pass, so all three are held alike).
#[test]
fn clearcoat_under_a_directional_light_matches_the_extension() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let lights = vec![
        Light::directional(Vec3::new(0.5, -0.4, -0.8), Vec3::new(1.0, 0.95, 0.9), 3.0),
        Light::ambient(Vec3::ONE, 0.05),
    ];
    let (_, o) = ibl::sphere_camera();
    let pixels = interior_pixels(&o, 1);
    for m in [coated(1.0, 0.3), coated(0.5, 0.5)] {
        let want: Vec<(u32, u32, Vec3)> = pixels
            .iter()
            .map(|&(x, y, n, v)| (x, y, layers::punctual_radiance(&m, n, n, v, &lights)))
            .collect();
        let what = format!(
            "clearcoat {} (roughness {}) under a directional light",
            m.clearcoat, m.clearcoat_roughness
        );
        let scene = layers::sphere(&m, lights.clone(), None);
        layers::check_techniques(
            ctx,
            &what,
            &scene,
            &want,
            Spread::Percentile99,
            (0.01, 0.03),
        );
    }
}

/// The coat's highlight is really there: against the same sphere without a
/// coat, the pixel of the mirror reflection of the light gains at least the
/// coat's lobe there (a check that the test above does not pass on a coat the
/// renderer ignores).
#[test]
fn the_coat_adds_its_own_highlight() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let lights = vec![Light::directional(
        Vec3::new(0.3, -0.3, -1.0),
        Vec3::ONE,
        3.0,
    )];
    let plain = layers::render(
        ctx,
        &layers::sphere(&coated(0.0, 0.2), lights.clone(), None),
        Technique::Deferred,
    );
    let coat = layers::render(
        ctx,
        &layers::sphere(&coated(1.0, 0.2), lights.clone(), None),
        Technique::Deferred,
    );
    let (_, o) = ibl::sphere_camera();
    let (mut best, mut at) = (0.0f32, (0, 0));
    for (x, y, _, _) in interior_pixels(&o, 1) {
        let i = (y * SPHERE_PX + x) as usize;
        let gain = coat[i][1] - plain[i][1];
        if gain > best {
            best = gain;
            at = (x, y);
        }
    }
    eprintln!("largest gain of the coat: {best:.3} at {at:?}");
    assert!(
        best > 1.0,
        "a roughness-0.2 coat under 3 lux must add a bright highlight, got {best}"
    );
}

/// A uniform environment of radiance 1 (no punctual light): every interior pixel
/// against the extension's formula integrated over the map's texels on the CPU
/// (the base's glTF BRDF with the renderer's multiple-scattering lobe, the coat's
/// D·V lobe). Mean relative error within 2 %, largest within 5 % in every
/// technique (the split-sum table's own error is about 0.01).
#[test]
fn clearcoat_under_a_constant_environment_matches_the_extension() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let env = Environment::new(EnvironmentSource::Uniform(Vec3::ONE));
    let t = ibl::texels(&Equirect::from_fn(256, |_| Vec3::ONE));
    let (_, o) = ibl::sphere_camera();
    let pixels = interior_pixels(&o, 4);
    for m in [coated(1.0, 0.3), coated(0.7, 0.6)] {
        let want: Vec<(u32, u32, Vec3)> = pixels
            .iter()
            .map(|&(x, y, n, v)| (x, y, layers::environment_radiance(&t, &m, n, v)))
            .collect();
        let what = format!(
            "clearcoat {} (roughness {}) in a uniform environment",
            m.clearcoat, m.clearcoat_roughness
        );
        let scene = layers::sphere(&m, vec![], Some(env.clone()));
        layers::check_techniques(ctx, &what, &scene, &want, Spread::Largest, (0.02, 0.05));
    }
}

/// `clearcoat = 0` is the material without the extension, bit for bit, in every
/// technique, with an environment and a light (the coat's roughness set to
/// something else must not matter).
#[test]
fn a_coat_of_strength_zero_is_the_plain_material() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let lights = vec![Light::directional(
        Vec3::new(0.5, -0.4, -0.8),
        Vec3::ONE,
        2.0,
    )];
    let env = Some(Environment::new(EnvironmentSource::Studio));
    let mut plain_scene = layers::sphere(&coated(0.0, 0.0), lights.clone(), env.clone());
    // the material as it was before the layers: no layer settings at all
    plain_scene.materials[0]
        .surface
        .params
        .retain(|(n, _)| !n.starts_with("clearcoat") && n != "transmission");
    let zero_scene = layers::sphere(&coated(0.0, 0.7), lights, env);
    for technique in Technique::ALL {
        let plain = layers::render(ctx, &plain_scene, technique);
        let zero = layers::render(ctx, &zero_scene, technique);
        let differ = plain.iter().zip(&zero).filter(|(a, b)| a != b).count();
        eprintln!("clearcoat 0 against no coat, {technique}: {differ} pixels differ");
        assert_eq!(differ, 0, "{technique}");
    }
}

/// The sphere through the CPU oracle of the core BRDF is what the coated
/// reference gives at clearcoat 0 (the two CPU references agree).
#[test]
fn the_references_agree_without_a_coat() {
    let lights = vec![Light::directional(
        Vec3::new(0.5, -0.4, -0.8),
        Vec3::ONE,
        2.0,
    )];
    let (_, o) = brdf::sphere_camera(32);
    let m = coated(0.0, 0.4);
    let core = render_sphere_oracle(
        &o,
        Vec3::ZERO,
        1.0,
        &Surface::metallic_roughness(m.base, 0.0, m.roughness),
        Model::CookTorrance,
        &lights,
    );
    for (i, c) in core.iter().enumerate() {
        let Some(c) = c else { continue };
        let (x, y) = (i as u32 % 32, i as u32 / 32);
        let (eye, d) = o.ray(x, y);
        let t = brdf::ray_sphere(eye, d, Vec3::ZERO, 1.0).unwrap();
        let n = (eye + d * t).normalize();
        let l = layers::punctual_radiance(&m, eye + d * t, n, -d, &lights);
        assert!((l - *c).abs().max_element() < 1e-6, "{l} against {c}");
    }
}

/// The extension's factors, textures (with texCoord and KHR_texture_transform)
/// and the coat normal's scale reach the standard surface's settings; a factor
/// outside [0, 1] or a missing texture is refused, naming the material.
#[test]
fn clearcoat_is_read_from_gltf() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = gltf_gen::spheres_gltf_json(&SpheresGltf {
        textured: true,
        ..Default::default()
    });
    doc["materials"][0]["extensions"] = json!({"KHR_materials_clearcoat": {
        "clearcoatFactor": 0.75,
        "clearcoatRoughnessFactor": 0.25,
        "clearcoatTexture": {"index": 0, "texCoord": 1},
        "clearcoatRoughnessTexture": {"index": 1, "extensions": {
            "KHR_texture_transform": {"offset": [0.5, 0.25]}
        }},
        "clearcoatNormalTexture": {"index": 1, "scale": 0.5}
    }});
    doc["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .push(json!("KHR_materials_clearcoat"));
    let path = gltf_gen::write_gltf(dir.path(), "coat.gltf", &doc);
    let scene = Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let m = &scene.materials[0];
    let param = |name: &str| layers::param(m, name);
    assert_eq!(param("clearcoat"), vec![0.75]);
    assert_eq!(param("clearcoat_roughness"), vec![0.25]);
    assert_eq!(param("clearcoat_normal_scale"), vec![0.5]);
    assert_eq!(param("clearcoat_map_uv_offset")[2], 1.0, "texCoord 1");
    assert_eq!(
        &param("clearcoat_roughness_map_uv_offset")[..2],
        &[0.5, 0.25]
    );
    let textures: Vec<&str> = m.surface.textures.iter().map(|(n, _)| n.as_str()).collect();
    for t in [
        "clearcoat_map",
        "clearcoat_roughness_map",
        "clearcoat_normal_map",
    ] {
        assert!(textures.contains(&t), "{t} not bound: {textures:?}");
    }
    // the other materials keep no coat
    assert!(!scene.materials[1]
        .surface
        .params
        .iter()
        .any(|(n, _)| n == "clearcoat"));
    // it renders
    if let Some(engine) = common::engine() {
        let mut r = Renderer::new(&engine.ctx, &scene, &RendererOptions::default()).unwrap();
        let (camera, _) = ibl::sphere_camera();
        r.render(&engine.ctx, &camera, 64, 64, Technique::Deferred, None)
            .unwrap();
    }

    for (ext, want) in [
        (
            json!({"clearcoatFactor": 1.5}),
            "clearcoatFactor 1.5 must be a number in [0, 1]",
        ),
        (
            json!({"clearcoatRoughnessFactor": "x"}),
            "clearcoatRoughnessFactor",
        ),
        (
            json!({"clearcoatFactor": 1, "clearcoatTexture": {"index": 9}}),
            "missing texture 9",
        ),
        (
            json!({"clearcoatFactor": 1, "clearcoatTexture": {"texCoord": 0}}),
            "needs an integer index",
        ),
    ] {
        let mut bad = doc.clone();
        bad["materials"][0]["extensions"]["KHR_materials_clearcoat"] = ext;
        let path = gltf_gen::write_gltf(dir.path(), "bad.gltf", &bad);
        let e = Scene::load(path.to_str().unwrap()).unwrap_err().to_string();
        eprintln!("{e}");
        assert!(e.contains("rough_dielectric") && e.contains(want), "{e}");
    }
}

/// A coated glTF sphere renders as the same material built by hand (the
/// extension's values reach the shader, not only the settings).
#[test]
fn a_coated_gltf_sphere_renders_its_coat() {
    let Some(engine) = common::engine() else {
        return;
    };
    let ctx = &engine.ctx;
    let dir = tempfile::tempdir().unwrap();
    let mut doc = gltf_gen::spheres_gltf_json(&SpheresGltf::default());
    doc["materials"][1]["extensions"] = json!({"KHR_materials_clearcoat": {
        "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.2
    }});
    let plain_path = gltf_gen::write_gltf(
        dir.path(),
        "plain.gltf",
        &gltf_gen::spheres_gltf_json(&SpheresGltf::default()),
    );
    let coat_path = gltf_gen::write_gltf(dir.path(), "coat.gltf", &doc);
    let shot = |path: &std::path::Path| {
        let scene = Scene::load(path.to_str().unwrap()).unwrap();
        let camera = scene.cameras[0].camera;
        let mut r = Renderer::new(ctx, &scene, &RendererOptions::default()).unwrap();
        let (out, _) = r
            .render(ctx, &camera, 160, 64, Technique::Forward, None)
            .unwrap();
        read_rgba_f32(ctx, &out.scene).unwrap()
    };
    let (plain, coat) = (shot(&plain_path), shot(&coat_path));
    // the middle sphere (columns 70..90 of 160 at this camera) changes, the
    // outer ones (49..69, 91..111) do not
    let (mut middle, mut outer) = (0.0f32, 0.0f32);
    for (i, (a, b)) in plain.iter().zip(&coat).enumerate() {
        let d = (a[0] - b[0])
            .abs()
            .max((a[1] - b[1]).abs())
            .max((a[2] - b[2]).abs());
        let x = i % 160;
        if (72..88).contains(&x) {
            middle = middle.max(d);
        } else if !(66..94).contains(&x) {
            outer = outer.max(d);
        }
    }
    eprintln!("coated middle sphere: largest change {middle:.3}, outer spheres {outer}");
    assert!(
        middle > 0.05 && outer == 0.0,
        "middle {middle}, outer {outer}"
    );
}
