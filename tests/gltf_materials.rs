//! glTF materials and lights (CPU only, no rendering): the metallic-roughness
//! mapping onto the `standard` surface and `cook_torrance` lighting, texture
//! transforms and coordinate sets, vertex colours, `KHR_lights_punctual`; and the
//! CPU BRDF oracle of tests/common/brdf.rs checked against itself and the glTF
//! specification.

use crate::common;

use common::brdf::{self, Model, OracleCamera, Surface};
use common::gltf_gen::{self, textured, GltfLight, SpheresGltf};
use fxgraph::scene::{AlphaMode, Camera, Light, LightKind, Material, Scene};
use glam::{Vec2, Vec3, Vec4};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

fn load(path: &Path) -> Scene {
    Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"))
}

fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}"))
}

fn param(m: &Material, name: &str) -> Vec<f32> {
    m.surface
        .param(name)
        .unwrap_or_else(|| panic!("{}: no parameter {name}", m.name))
        .iter()
        .map(|v| *v as f32)
        .collect()
}

fn assert_close(a: &[f32], b: &[f32], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: {a:?} vs {b:?}");
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= tol, "{what}: {a:?} vs {b:?}");
    }
}

/// The texture bound to `var` of `m`, by name.
fn texture_name<'a>(scene: &'a Scene, m: &Material, var: &str) -> &'a str {
    let t = m
        .surface
        .texture(var)
        .unwrap_or_else(|| panic!("{}: no texture {var}", m.name));
    &scene.textures[t].name
}

/// The KHR_texture_transform matrix (columns) of the extension: `R(r) · S(s)` with
/// `R = [[cos, sin], [−sin, cos]]` (rows), the rotation that maps the published
/// example onto the lower-left quadrant (see `texture_transform_follows_the_published_example`).
fn expected_uv(rotation: f32, scale: [f32; 2]) -> [f32; 4] {
    let (s, c) = rotation.sin_cos();
    [c * scale[0], -s * scale[0], s * scale[1], c * scale[1]]
}

fn write_variant(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut json = gltf_gen::spheres_gltf_json(&SpheresGltf {
        light: gltf_gen::DIRECTIONAL,
        textured: true,
    });
    edit(&mut json);
    gltf_gen::write_gltf(dir, name, &json)
}

// ------------------------------------------------------------ glTF loading

#[test]
fn sphere_materials_follow_the_spec() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&gltf_gen::write_spheres_gltf(dir.path()));
    assert_eq!(scene.materials.len(), 3);
    assert!(scene.textures.is_empty());
    for (spec, centre) in gltf_gen::SPHERE_MATERIALS
        .iter()
        .zip(gltf_gen::SPHERE_CENTRES)
    {
        let m = material(&scene, spec.name);
        assert_eq!(m.surface.shader, "standard");
        assert_eq!(m.lighting.shader, "cook_torrance");
        assert!(m.lighting.params.is_empty() && m.lighting.textures.is_empty());
        assert_close(
            &param(m, "base_color"),
            &spec.base_color,
            1e-6,
            "base_color",
        );
        assert_close(&param(m, "metallic"), &[spec.metallic], 1e-6, "metallic");
        assert_close(&param(m, "roughness"), &[spec.roughness], 1e-6, "roughness");
        assert_close(&param(m, "emissive"), &[0.0; 3], 0.0, "emissive");
        assert_close(
            &param(m, "specular"),
            &[0.04; 3],
            1e-6,
            "specular (ior 1.5)",
        );
        assert!(m.surface.textures.is_empty(), "{:?}", m.surface.textures);
        assert!(m.surface.param("normal_scale").is_none());
        assert_eq!(m.alpha_mode, AlphaMode::Opaque);
        assert_eq!(m.alpha_cutoff, 0.5);
        assert!(!m.double_sided);
        let index = scene.materials.iter().position(|x| x.name == spec.name);
        let inst = scene
            .instances
            .iter()
            .find(|i| Some(i.material) == index)
            .unwrap();
        assert!(inst.transform.transform_point3(Vec3::ZERO).distance(centre) < 1e-6);
        let mesh = &scene.meshes[inst.mesh];
        assert!(mesh.uvs1.is_empty() && mesh.colors.is_empty());
        // Counter-clockwise seen from outside (glTF front faces), unit normals.
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "{t:?}");
        }
        assert!(mesh
            .normals
            .iter()
            .zip(&mesh.positions)
            .all(|(n, p)| n.distance(*p) < 1e-5));
    }
    // The camera of the file.
    let cam = scene.cameras[0].camera;
    assert!(cam.eye.distance(gltf_gen::CAMERA_EYE) < 1e-6);
    assert!((cam.target - cam.eye).normalize().distance(Vec3::NEG_Z) < 1e-6);
    assert!((cam.fov_y - gltf_gen::CAMERA_FOV_Y).abs() < 1e-6);
    // The directional light: lux as given, no attenuation, no range.
    assert_eq!(scene.lights.len(), 1);
    let l = &scene.lights[0];
    let GltfLight::Directional {
        direction,
        color,
        intensity,
    } = gltf_gen::DIRECTIONAL
    else {
        unreachable!()
    };
    assert_eq!(l.kind, LightKind::Directional);
    assert!(
        l.direction.distance(direction.normalize()) < 1e-5,
        "{}",
        l.direction
    );
    assert_eq!((l.color, l.intensity, l.range), (color, intensity, None));
}

#[test]
fn point_light_keeps_candela_inverse_square_and_range() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&gltf_gen::write_spheres_gltf_point(dir.path()));
    let GltfLight::Point {
        position,
        color,
        intensity,
        range,
    } = gltf_gen::POINT
    else {
        unreachable!()
    };
    assert_eq!(scene.lights.len(), 1);
    let l = &scene.lights[0];
    assert_eq!(l.kind, LightKind::Point);
    assert!(l.position.distance(position) < 1e-6);
    assert_eq!((l.color, l.intensity), (color, intensity));
    assert_eq!(l.attenuation, [0.0, 0.0, 1.0], "pure inverse square");
    assert_eq!(l.range, range);
    assert!(l.radius() <= range.unwrap());
    // The oracle's falloff of this light: I / d², times the range window.
    let p = position + Vec3::new(0.0, 0.0, -3.0);
    let (dir_to_light, e) = brdf::illuminance(l, p, false).unwrap();
    let window = 1.0 - (3.0f32 / range.unwrap()).powi(4);
    assert!(dir_to_light.distance(Vec3::Z) < 1e-6);
    assert!((e - color * intensity / 9.0 * window).abs().max_element() < 1e-5);
}

#[test]
fn textured_material_maps_every_texture() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&gltf_gen::write_spheres_gltf_textured(dir.path()));
    assert_eq!(scene.materials.len(), 4);
    assert_eq!(scene.textures.len(), 2, "one texture per image");
    let m = material(&scene, textured::NAME);
    let [checker, orm] = textured::IMAGE_NAMES;
    for (var, image) in [
        ("base_color_map", checker),
        ("emissive_map", checker),
        ("metallic_roughness_map", orm),
        ("normal_map", orm),
        ("occlusion_map", orm),
    ] {
        assert_eq!(texture_name(&scene, m, var), image, "{var}");
    }
    assert_eq!(m.surface.textures.len(), 5);
    let emissive = textured::EMISSIVE.map(|e| e * textured::EMISSIVE_STRENGTH);
    let params: [(&str, &[f32], &str); 6] = [
        ("base_color", &textured::BASE_COLOR, "base"),
        ("metallic", &[textured::METALLIC], "metallic"),
        ("roughness", &[textured::ROUGHNESS], "rough"),
        ("emissive", &emissive, "emissive × strength"),
        ("normal_scale", &[textured::NORMAL_SCALE], "ns"),
        (
            "occlusion_strength",
            &[textured::OCCLUSION_STRENGTH],
            "occlusion strength",
        ),
    ];
    for (name, want, what) in params {
        assert_close(&param(m, name), want, 1e-6, what);
    }
    assert_eq!(m.alpha_mode, AlphaMode::Mask);
    assert!((m.alpha_cutoff - textured::ALPHA_CUTOFF).abs() < 1e-6);
    assert!(m.double_sided);
    // Texture coordinate sets and transforms.
    let [ox, oy] = textured::BASE_OFFSET;
    let expect: [(&str, [f32; 4], [f32; 4]); 5] = [
        (
            "base_color_map",
            expected_uv(textured::BASE_ROTATION, textured::BASE_SCALE),
            [ox, oy, 1.0, 0.0], // texCoord 0 overridden by the extension
        ),
        (
            "metallic_roughness_map",
            [1.0, 0.0, 0.0, 1.0],
            [textured::MR_OFFSET[0], textured::MR_OFFSET[1], 0.0, 0.0],
        ),
        (
            "normal_map",
            expected_uv(textured::NORMAL_ROTATION, [1.0, 1.0]),
            [0.0, 0.0, 1.0, 0.0],
        ),
        ("occlusion_map", [1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]),
        ("emissive_map", [1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0]),
    ];
    for (var, uv, offset) in expect {
        assert_close(&param(m, &format!("{var}_uv")), &uv, 1e-6, var);
        assert_close(&param(m, &format!("{var}_uv_offset")), &offset, 1e-6, var);
    }
    // The base colour transform by hand: rotation 30°, scale (2, 3).
    let (s, c) = (0.5f32, 3f32.sqrt() / 2.0);
    assert_close(
        &param(m, "base_color_map_uv"),
        &[2.0 * c, -2.0 * s, 3.0 * s, 3.0 * c],
        1e-6,
        "30° matrix",
    );
    // TEXCOORD_1 and COLOR_0 of the textured sphere.
    let index = scene
        .materials
        .iter()
        .position(|x| x.name == textured::NAME);
    let inst = scene
        .instances
        .iter()
        .find(|i| Some(i.material) == index)
        .unwrap();
    let mesh = &scene.meshes[inst.mesh];
    assert_eq!(mesh.uvs1.len(), mesh.positions.len());
    for (u0, u1) in mesh.uvs.iter().zip(&mesh.uvs1) {
        assert_eq!(*u1, gltf_gen::uv1_of(*u0));
    }
    assert_eq!(mesh.colors.len(), mesh.positions.len());
    let [r, g, b] = textured::COLOR_0_U8.map(|c| c as f32 / 255.0);
    assert!(mesh
        .colors
        .iter()
        .all(|c| c.abs_diff_eq(Vec4::new(r, g, b, 1.0), 1e-6)));
    // The normal map reads set 1: tangents exist (derived from TEXCOORD_1).
    let tangents = mesh.tangents.as_ref().expect("tangents");
    assert!(tangents.iter().filter(|t| t.w != 0.0).count() > mesh.positions.len() / 2);
    // The untextured spheres' meshes have neither.
    let plain = scene
        .instances
        .iter()
        .find(|i| i.material != index.unwrap())
        .unwrap();
    assert!(scene.meshes[plain.mesh].uvs1.is_empty());
}

/// The extension's published example: offset (0, 1), rotation π/2, scale 0.5 "utilizes
/// only the lower left quadrant of the source image, rotated clockwise 90°" (UV
/// (0, 0) is the image's top-left corner, so the lower-left quadrant is
/// u ∈ [0, 0.5], v ∈ [0.5, 1]).
#[test]
fn texture_transform_follows_the_published_example() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_variant(dir.path(), "example.gltf", |j| {
        j["materials"][3]["emissiveTexture"] = serde_json::json!({
            "index": 0,
            "extensions": {"KHR_texture_transform": {
                "offset": [0, 1], "rotation": std::f64::consts::FRAC_PI_2, "scale": [0.5, 0.5]
            }}
        });
    });
    let scene = load(&path);
    let m = material(&scene, textured::NAME);
    let a = param(m, "emissive_map_uv");
    let o = param(m, "emissive_map_uv_offset");
    let apply = |uv: Vec2| {
        Vec2::new(
            a[0] * uv.x + a[2] * uv.y + o[0],
            a[1] * uv.x + a[3] * uv.y + o[1],
        )
    };
    // The corners of the unit square land on the corners of the lower-left quadrant.
    let mut corners: Vec<Vec2> = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE]
        .into_iter()
        .map(apply)
        .collect();
    for c in &corners {
        assert!(
            (-1e-6..=0.5 + 1e-6).contains(&c.x) && (0.5 - 1e-6..=1.0 + 1e-6).contains(&c.y),
            "{corners:?}"
        );
    }
    // Rotated clockwise 90° (as the image appears): the image's top edge (v = 0)
    // comes from the quadrant's left edge (u' = 0), top-left (0,0) from its
    // bottom-left corner (0, 1).
    assert!(
        corners[0].distance(Vec2::new(0.0, 1.0)) < 1e-6,
        "{corners:?}"
    );
    assert!(
        corners[1].distance(Vec2::new(0.0, 0.5)) < 1e-6,
        "{corners:?}"
    );
    assert!(
        corners[2].distance(Vec2::new(0.5, 1.0)) < 1e-6,
        "{corners:?}"
    );
    corners.dedup();
    assert_eq!(corners.len(), 4);
}

#[test]
fn texcoord_sets_above_one_read_set_zero() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_variant(dir.path(), "texcoord2.gltf", |j| {
        j["materials"][3]["occlusionTexture"]["texCoord"] = serde_json::json!(2);
    });
    let scene = load(&path);
    let m = material(&scene, textured::NAME);
    assert_eq!(param(m, "occlusion_map_uv_offset")[2], 0.0);
}

#[test]
fn punctual_light_validation() {
    let dir = tempfile::tempdir().unwrap();
    let set = |key: &'static str, value: serde_json::Value| {
        move |j: &mut serde_json::Value| {
            j["extensions"]["KHR_lights_punctual"]["lights"][0][key] = value;
        }
    };
    let bad = write_variant(
        dir.path(),
        "negative.gltf",
        set("intensity", serde_json::json!(-1.0)),
    );
    let e = Scene::load(bad.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        e.contains("negative.gltf") && e.contains("intensity"),
        "{e}"
    );
    let zero = write_variant(
        dir.path(),
        "zero.gltf",
        set("intensity", serde_json::json!(0.0)),
    );
    let s = load(&zero);
    assert_eq!(
        s.lights.len(),
        1,
        "kept (with a warning), no default lights"
    );
    assert_eq!(s.lights[0].intensity, 0.0);
    let range = write_variant(dir.path(), "range.gltf", |j| {
        let l = &mut j["extensions"]["KHR_lights_punctual"]["lights"][0];
        l["type"] = "point".into();
        l["range"] = serde_json::json!(0.0);
    });
    let e = Scene::load(range.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("range"), "{e}");
}

#[test]
fn flight_helmet_maps_its_textures() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus/gltf/FlightHelmet/FlightHelmet.gltf");
    if !path.is_file() {
        eprintln!("skipping: {} is absent", path.display());
        return;
    }
    let scene = load(&path);
    assert_eq!(scene.materials.len(), 6);
    for (name, prefix) in [
        ("HoseMat", "RubberWoodMat"),
        ("RubberWoodMat", "RubberWoodMat"),
        ("GlassPlasticMat", "GlassPlasticMat"),
        ("MetalPartsMat", "MetalPartsMat"),
        ("LeatherPartsMat", "LeatherPartsMat"),
        ("LensesMat", "LensesMat"),
    ] {
        let m = material(&scene, name);
        assert_eq!(
            (m.surface.shader.as_str(), m.lighting.shader.as_str()),
            ("standard", "cook_torrance")
        );
        for (var, suffix) in [
            ("base_color_map", "BaseColor"),
            ("normal_map", "Normal"),
            ("metallic_roughness_map", "OcclusionRoughMetal"),
            ("occlusion_map", "OcclusionRoughMetal"),
        ] {
            let t = texture_name(&scene, m, var);
            assert_eq!(
                t,
                format!("FlightHelmet_Materials_{prefix}_{suffix}.png"),
                "{name}"
            );
            assert_close(
                &param(m, &format!("{var}_uv")),
                &[1.0, 0.0, 0.0, 1.0],
                0.0,
                var,
            );
            assert_close(&param(m, &format!("{var}_uv_offset")), &[0.0; 4], 0.0, var);
        }
        assert_eq!(m.surface.textures.len(), 4, "{name}");
        // Factors absent: the spec's defaults.
        assert_close(&param(m, "base_color"), &[1.0; 4], 0.0, "base");
        assert_close(&param(m, "metallic"), &[1.0], 0.0, "metallic");
        assert_close(&param(m, "roughness"), &[1.0], 0.0, "roughness");
        assert_close(&param(m, "normal_scale"), &[1.0], 0.0, "normal scale");
        assert_close(&param(m, "occlusion_strength"), &[1.0], 0.0, "strength");
        let blend = name == "LensesMat";
        assert_eq!(m.alpha_mode == AlphaMode::Blend, blend, "{name}");
        assert_eq!(m.double_sided, name == "HoseMat", "{name}");
    }
    // Every textured mesh has tangents (from the file).
    assert!(scene.meshes.iter().all(|m| m.tangents.is_some()));
}

// ------------------------------------------------------------ the oracle

/// A white Lambert surface under 1 lux at normal incidence reflects 1/π.
#[test]
fn oracle_lambert_energy() {
    let (d, s) = brdf::lambert(Vec3::Z, Vec3::Z, Vec3::ONE);
    assert!((d - Vec3::splat(1.0 / PI)).abs().max_element() < 1e-7);
    assert_eq!(s, Vec3::ZERO);
    let sun = Light::directional(Vec3::NEG_Z, Vec3::ONE, 1.0);
    let white = Surface::new(Vec3::ONE, Vec3::ZERO, 1.0);
    let l = brdf::radiance(
        &white,
        Model::Lambert,
        Vec3::ZERO,
        Vec3::Z,
        Vec3::Z,
        &[sun],
        true,
    );
    assert!((l - Vec3::splat(1.0 / PI)).abs().max_element() < 1e-7);
    // Ambient: colour × intensity × occlusion × diffuse.
    let amb = Light::ambient(Vec3::new(1.0, 0.5, 0.25), 0.4);
    let s = Surface {
        occlusion: 0.5,
        emission: Vec3::new(0.0, 0.0, 0.1),
        ..Surface::new(Vec3::splat(0.5), Vec3::ZERO, 1.0)
    };
    let l = brdf::radiance(
        &s,
        Model::Lambert,
        Vec3::ZERO,
        Vec3::Z,
        Vec3::Z,
        &[amb],
        true,
    );
    assert!(
        (l - Vec3::new(0.1, 0.05, 0.025 + 0.1)).abs().max_element() < 1e-7,
        "{l}"
    );
}

fn directions() -> Vec<Vec3> {
    let mut rng = fxgraph::scene::Rng::new(5);
    (0..200)
        .map(|_| {
            let z = rng.next_f32();
            let phi = 2.0 * PI * rng.next_f32();
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z.max(0.02)).normalize()
        })
        .collect()
}

#[test]
fn oracle_cook_torrance_is_reciprocal() {
    let dirs = directions();
    let f0 = Vec3::new(0.04, 0.5, 0.95);
    for rough in [0.1, 0.5, 1.0] {
        for pair in dirs.chunks_exact(2) {
            let (a, b) = (pair[0], pair[1]);
            let (da, sa) = brdf::cook_torrance(f0, rough, Vec3::Z, a, b, Vec3::ONE);
            let (db, sb) = brdf::cook_torrance(f0, rough, Vec3::Z, b, a, Vec3::ONE);
            // f(l, v) = out / ndl must be symmetric.
            let (fa, fb) = (sa / b.z, sb / a.z);
            assert!(
                (fa - fb).abs().max_element() <= 1e-4 * fa.max_element().max(1.0),
                "{fa} vs {fb}"
            );
            assert!(((da / b.z) - (db / a.z)).abs().max_element() < 1e-5);
        }
    }
}

#[test]
fn oracle_white_furnace() {
    let normal = Vec3::Z;
    let oblique = Vec3::new(0.866, 0.0, 0.5);
    // Lambert reflects all of a uniform environment.
    let (d, _) = brdf::hemisphere_albedo(Model::Lambert, Vec3::ZERO, 1.0, normal, 256);
    assert!((d.x - 1.0).abs() < 1e-3, "{d}");
    // Normalised Phong with F0 = 1 seen along the normal: exactly 1.
    let (_, s) = brdf::hemisphere_albedo(Model::Phong(32.0), Vec3::ONE, 1.0, normal, 512);
    assert!((s.x - 1.0).abs() < 5e-3, "Phong {s}");
    // Blinn-Phong's (p + 8)/(8π) is an approximate normalisation.
    let (_, s) = brdf::hemisphere_albedo(Model::BlinnPhong(32.0), Vec3::ONE, 1.0, normal, 512);
    assert!((0.85..1.1).contains(&s.x), "Blinn-Phong {s}");
    for v in [normal, oblique] {
        for rough in [0.3, 0.6, 1.0] {
            // A white (F0 = 1) GGX lobe never creates energy; a smooth one loses
            // little (single scattering only: rough ones lose much).
            let (_, s) = brdf::hemisphere_albedo(Model::CookTorrance, Vec3::ONE, rough, v, 512);
            assert!(s.x <= 1.0 + 2e-3, "CT roughness {rough}, v {v}: {s}");
            if rough <= 0.3 {
                assert!(s.x > 0.97, "CT roughness {rough}, v {v}: {s}");
            }
            // A white dielectric, diffuse (1 − F)/π plus specular: the glTF
            // implementation's (1 − F(v·h)) weighting is not exactly energy
            // conserving (1.025 at 60° and roughness 0.3), but close; below 1 seen
            // along the normal.
            let (d, s) =
                brdf::hemisphere_albedo(Model::CookTorrance, Vec3::splat(0.04), rough, v, 512);
            let limit = if v == normal { 1.0 + 2e-3 } else { 1.03 };
            assert!(
                d.x + s.x <= limit,
                "dielectric roughness {rough}, v {v}: {d} + {s}"
            );
            assert!(
                d.x + s.x > 0.95,
                "dielectric roughness {rough}, v {v}: {d} + {s}"
            );
        }
    }
    // Roughness 1 (α = 1) seen along the normal has a closed form: D = 1/π,
    // V = 0.5/(μ + 1), so the albedo is ∫₀¹ μ/(μ + 1) dμ = 1 − ln 2.
    let (_, s) = brdf::hemisphere_albedo(Model::CookTorrance, Vec3::ONE, 1.0, normal, 512);
    assert!((s.x - (1.0 - 2f32.ln())).abs() < 1e-3, "{s}");
}

/// The implementation form of Appendix B (`cook_torrance` on the metallic-roughness
/// surface) equals the specification's `mix(dielectric_brdf, metal_brdf, metallic)`
/// at metallic 0 and 1. In between only the diffuse term differs: the spec form
/// has `(1 − m)·base/π·(1 − F_dielectric)`, the implementation
/// `(1 − m)·base/π·(1 − F)` with `F = mix(F_dielectric, F_metal, m)`, i.e. at
/// metallic 0.5 it reflects `0.25·base/π·(F_metal − F_dielectric)·ndl` less. For a
/// white base at normal incidence that is 0.25/π·0.96 = 0.0764 of 0.1528 + specular:
/// the implementation's diffuse is half of the spec form's (the specular terms are
/// identical because F is linear in F0).
#[test]
fn gltf_spec_forms_agree() {
    let dirs = directions();
    for base in [Vec3::ONE, Vec3::new(0.9, 0.5, 0.1), Vec3::splat(0.04)] {
        for rough in [0.2, 0.5, 0.9] {
            for pair in dirs.chunks_exact(2) {
                let (v, l) = (pair[0], pair[1]);
                let form = |metallic: f32| {
                    let s = Surface::metallic_roughness(base, metallic, rough);
                    let (d, sp) = brdf::cook_torrance(s.f0, rough, Vec3::Z, v, l, Vec3::ONE);
                    s.diffuse * d + sp
                };
                for metallic in [0.0, 1.0] {
                    let a = form(metallic);
                    let b = brdf::gltf_spec_brdf(base, metallic, rough, Vec3::Z, v, l);
                    assert!(
                        (a - b).abs().max_element() <= 1e-5 * a.max_element().max(1.0),
                        "metallic {metallic}: {a} vs {b}"
                    );
                }
                // Metallic 0.5: the difference is exactly the diffuse one above.
                let a = form(0.5);
                let b = brdf::gltf_spec_brdf(base, 0.5, rough, Vec3::Z, v, l);
                let w = (1.0 - v.dot((v + l).normalize()).abs()).powi(5);
                let (f_d, f_m) = (Vec3::splat(0.04 + 0.96 * w), base + (Vec3::ONE - base) * w);
                let expected = 0.25 * base / PI * (f_m - f_d) * l.z;
                assert!(
                    ((b - a) - expected).abs().max_element() <= 1e-5 * b.max_element().max(1.0),
                    "metallic 0.5: spec {b} impl {a}, expected difference {expected}"
                );
            }
        }
    }
    // The figure quoted above.
    let spec = brdf::gltf_spec_brdf(Vec3::ONE, 0.5, 0.5, Vec3::Z, Vec3::Z, Vec3::Z);
    let s = Surface::metallic_roughness(Vec3::ONE, 0.5, 0.5);
    let (d, sp) = brdf::cook_torrance(s.f0, 0.5, Vec3::Z, Vec3::Z, Vec3::Z, Vec3::ONE);
    let imp = s.diffuse * d + sp;
    assert!(
        ((spec - imp).x - 0.25 / PI * 0.96).abs() < 1e-5,
        "{spec} {imp}"
    );
}

#[test]
fn oracle_light_attenuation() {
    let p = Vec3::ZERO;
    // Directional: colour × intensity (lux) from −direction.
    let sun = Light::directional(Vec3::new(0.0, -1.0, 0.0), Vec3::new(1.0, 0.5, 0.25), 2.0);
    let (l, e) = brdf::illuminance(&sun, p, true).unwrap();
    assert!(l.distance(Vec3::Y) < 1e-6 && e.distance(Vec3::new(2.0, 1.0, 0.5)) < 1e-6);
    // Point (glTF): I / d², range window 1 − (d/range)⁴, nothing beyond the range.
    let point = Light {
        attenuation: [0.0, 0.0, 1.0],
        range: Some(4.0),
        ..Light::point(Vec3::new(0.0, 2.0, 0.0), Vec3::ONE, 10.0, 100.0)
    };
    let (l, e) = brdf::illuminance(&point, p, false).unwrap();
    assert!(l.distance(Vec3::Y) < 1e-6);
    assert!(
        (e.x - 10.0 / 4.0 * (1.0 - 0.5f32.powi(4))).abs() < 1e-5,
        "{e}"
    );
    let far = Vec3::new(0.0, -2.5, 0.0); // d = 4.5 > range
    assert_eq!(brdf::illuminance(&point, far, false).unwrap().1, Vec3::ZERO);
    let no_range = Light {
        range: None,
        ..point.clone()
    };
    let (_, e) = brdf::illuminance(&no_range, far, false).unwrap();
    assert!((e.x - 10.0 / 4.5 / 4.5).abs() < 1e-6);
    // Spot: t² between the cones.
    let (inner, outer) = (0.2f32, 0.6f32);
    let spot = Light {
        kind: LightKind::Spot { inner, outer },
        direction: Vec3::NEG_Y,
        ..no_range.clone()
    };
    let at = |angle: f32| {
        let q = spot.position + 2.0 * Vec3::new(angle.sin(), -angle.cos(), 0.0);
        brdf::illuminance(&spot, q, false).unwrap().1.x
    };
    assert!((at(0.1) - 10.0 / 4.0).abs() < 1e-5, "inside the inner cone");
    assert_eq!(at(0.7), 0.0, "outside the outer cone");
    let t = (0.4f32.cos() - outer.cos()) / (inner.cos() - outer.cos());
    assert!(
        (at(0.4) - 10.0 / 4.0 * t * t).abs() < 1e-5,
        "{} {}",
        at(0.4),
        t
    );
    // The scene model's ε cut-off (Light::radius) when asked for.
    let weak = Light {
        intensity: 0.01,
        ..no_range.clone()
    };
    let beyond = Vec3::new(0.0, 2.0 + weak.radius() + 0.1, 0.0);
    assert!(brdf::illuminance(&weak, beyond, true).is_none());
    assert!(brdf::illuminance(&weak, beyond, false).is_some());
    // Ambient lights have no direction.
    assert!(brdf::illuminance(&Light::ambient(Vec3::ONE, 1.0), p, true).is_none());
}

/// The oracle's rays go through the pixel centres the renderer's matrices
/// (`Camera::view`, `perspective_rh`) project to.
#[test]
fn oracle_camera_matches_the_renderer() {
    let camera = Camera {
        eye: Vec3::new(1.0, 2.0, 5.0),
        target: Vec3::new(-0.5, 0.2, 0.0),
        up: Vec3::Y,
        fov_y: 0.8,
        near: 0.1,
        far: 100.0,
    };
    let cam = OracleCamera::of(&camera, 160, 90);
    let view_proj = camera.proj(cam.aspect) * camera.view();
    for (x, y) in [(0, 0), (159, 0), (80, 45), (17, 83), (159, 89)] {
        let (o, d) = cam.ray(x, y);
        let clip = view_proj * (o + d * 3.0).extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let px = (ndc.x + 1.0) * 0.5 * cam.width as f32;
        let py = (1.0 - ndc.y) * 0.5 * cam.height as f32;
        assert!(
            (px - (x as f32 + 0.5)).abs() < 1e-3 && (py - (y as f32 + 0.5)).abs() < 1e-3,
            "pixel ({x}, {y}) -> ({px}, {py})"
        );
    }
}

#[test]
fn oracle_renders_a_sphere() {
    let (w, h) = (64, 48);
    let cam = OracleCamera::of(&gltf_gen::camera(), w, h);
    let surface = Surface::new(Vec3::new(0.5, 0.25, 1.0), Vec3::ZERO, 1.0);
    // Light from the eye: the sphere's centre pixel sees n = l = v.
    let sun = Light::directional(Vec3::NEG_Z, Vec3::ONE, 2.0);
    let img = brdf::render_sphere_oracle(&cam, Vec3::ZERO, 1.0, &surface, Model::Lambert, &[sun]);
    assert_eq!(img.len(), (w * h) as usize);
    assert!(
        img[0].is_none() && img[(w * h - 1) as usize].is_none(),
        "corners miss"
    );
    let centre = img[(h / 2 * w + w / 2) as usize].unwrap();
    // Pixel (32, 24) is half a pixel off the axis: cos θ ≈ 1.
    let expected = surface.diffuse * 2.0 / PI;
    assert!(
        ((centre / expected) - Vec3::ONE).abs().max_element() < 0.01,
        "{centre}"
    );
    // The sphere's silhouette: radius 1 at distance 8 covers asin(1/8) of the view.
    let covered = img.iter().filter(|p| p.is_some()).count() as f32;
    let half = (1.0f32 / 8.0).asin().tan() / (cam.fov_y * 0.5).tan() * h as f32 * 0.5;
    let expected = PI * half * half;
    assert!(
        (covered / expected - 1.0).abs() < 0.1,
        "{covered} vs {expected}"
    );
    // Brightness falls off towards the rim.
    let row = &img[(h / 2 * w) as usize..((h / 2 + 1) * w) as usize];
    let lit: Vec<f32> = row.iter().flatten().map(|c| c.x).collect();
    assert!(lit.first().unwrap() < &(centre.x * 0.6), "{lit:?}");
}
