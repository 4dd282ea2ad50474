//! The material system on lavapipe: every lighting shader against the CPU oracle
//! (tests/common/brdf.rs) on an analytic sphere, glTF metallic-roughness spheres
//! against the glTF 2.0 specification, forward = deferred = light pre-pass for
//! every (surface, lighting) pair of the library and a user pair, identical images
//! in the three variant modes, and the variant cache counts.

use crate::common;

use common::bench;
use common::brdf::{self, Model, OracleCamera, Surface};
use common::gltf_gen;
use common::gpu_context;
use common::renders::{assert_psnr, save_rgb_review};
use common::scenes::one_object;
use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::material::VariantMode;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::builtin::{box_mesh, uv_sphere};
use fxgraph::scene::material_file::{apply_materials, load_materials};
use fxgraph::scene::{Camera, Instance, Light, Material, Scene, ShaderBinding};
use glam::{Mat4, Vec3, Vec4};

/// A renderer of `scene` whose material variants are made as `variants` says.
fn renderer(ctx: &GpuContext, scene: &Scene, variants: VariantMode) -> Renderer {
    let options = RendererOptions {
        variants,
        ..Default::default()
    };
    Renderer::new(ctx, scene, &options).unwrap_or_else(|e| panic!("{}: {e}", scene.name))
}

/// `scene` seen from `camera`, rendered and read back (HDR RGBA).
fn render(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    (w, h): (u32, u32),
    technique: Technique,
    variants: VariantMode,
) -> Vec<[f32; 4]> {
    let mut r = renderer(ctx, scene, variants);
    let (out, _) = r
        .render(ctx, camera, w, h, technique, None)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    read_rgba_f32(ctx, &out.scene).unwrap()
}

/// [`render`] as every other technique and variant mode is compared against:
/// deferred, with preprocessed variants.
fn reference(ctx: &GpuContext, scene: &Scene, camera: &Camera, size: (u32, u32)) -> Vec<[f32; 4]> {
    render(
        ctx,
        scene,
        camera,
        size,
        Technique::Deferred,
        VariantMode::Preprocess,
    )
}

/// [`reference`] of `scene` seen from the camera `spec` at `size`, written to
/// tests/output/NAME.png for review: the camera and the image.
fn reviewed_reference(
    ctx: &GpuContext,
    scene: &Scene,
    spec: &str,
    size: (u32, u32),
    name: &str,
) -> (Camera, Vec<[f32; 4]>) {
    let camera = Camera::parse_spec(spec, scene).unwrap();
    let image = reference(ctx, scene, &camera, size);
    save_rgb_review(name, size, &image);
    (camera, image)
}

/// Per-pixel comparison with the oracle over the sphere's interior (pixels whose
/// four neighbours also hit, so silhouette coverage does not count): the error
/// relative to max(reference, `floor`), per channel. Returns (99th percentile,
/// mean, pixels compared).
fn oracle_error(
    gpu: &[[f32; 4]],
    oracle: &[Option<Vec3>],
    (w, h): (u32, u32),
    floor: f32,
) -> (f32, f32, usize) {
    let mut errs = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = (y * w + x) as usize;
            let inside = [i, i - 1, i + 1, i - w as usize, i + w as usize]
                .iter()
                .all(|&j| oracle[j].is_some());
            if !inside {
                continue;
            }
            let r = oracle[i].unwrap();
            for c in 0..3 {
                errs.push((gpu[i][c] - r[c]).abs() / r[c].max(floor));
            }
        }
    }
    errs.sort_by(f32::total_cmp);
    let p99 = errs[(errs.len() as f64 * 0.99) as usize];
    let mean = errs.iter().sum::<f32>() / errs.len() as f32;
    (p99, mean, errs.len() / 3)
}

const SPHERE_SIZE: (u32, u32) = (160, 160);

fn sphere_scene(material: Material, lights: Vec<Light>) -> Scene {
    let name = format!("sphere ({})", material.lighting.shader);
    let mut scene = one_object(name, "sphere", uv_sphere(192, 96), material, Mat4::IDENTITY);
    scene.lights = lights;
    scene
}

fn sphere_camera() -> (Camera, OracleCamera) {
    brdf::sphere_camera(SPHERE_SIZE.0)
}

/// A directional key light, a glTF-style point light (inverse square) and a dim
/// ambient light.
fn test_lights() -> Vec<Light> {
    let mut point = Light::point(
        Vec3::new(-2.0, 1.5, 2.5),
        Vec3::new(1.0, 0.8, 0.6),
        12.0,
        1.0,
    );
    point.attenuation = [0.0, 0.0, 1.0];
    vec![
        Light::directional(Vec3::new(0.5, -0.6, -0.6), Vec3::new(0.9, 0.95, 1.0), 2.5),
        point,
        Light::ambient(Vec3::ONE, 0.05),
    ]
}

#[test]
fn every_lighting_shader_matches_the_cpu_oracle_on_a_sphere() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let (camera, ocam) = sphere_camera();
    let base = Vec3::new(0.7, 0.45, 0.3);
    let cases: Vec<(&str, Material, Surface, Model)> = vec![
        (
            "lambert",
            Material::new(
                "lambert",
                ShaderBinding::new("standard").with("base_color", &[0.7, 0.45, 0.3, 1.0]),
                ShaderBinding::new("lambert"),
            ),
            Surface::new(base, Vec3::splat(0.04), 0.5),
            Model::Lambert,
        ),
        (
            "phong",
            Material::phong("phong", base, 0.3, 24.0),
            Surface::new(
                base,
                Vec3::splat(0.3),
                fxgraph::scene::roughness_from_shininess(24.0),
            ),
            Model::Phong(24.0),
        ),
        (
            "blinn_phong",
            Material::new(
                "blinn",
                ShaderBinding::new("standard")
                    .with("base_color", &[0.7, 0.45, 0.3, 1.0])
                    .with("specular", &[0.25, 0.25, 0.25]),
                ShaderBinding::new("blinn_phong").with("shininess", &[48.0]),
            ),
            Surface::new(base, Vec3::splat(0.25), 0.5),
            Model::BlinnPhong(48.0),
        ),
        (
            "cook_torrance dielectric",
            Material::metallic_roughness("ct", base.extend(1.0), 0.0, 0.35),
            Surface::metallic_roughness(base, 0.0, 0.35),
            Model::CookTorrance,
        ),
        (
            "cook_torrance metal",
            Material::metallic_roughness("gold", Vec4::new(1.0, 0.77, 0.34, 1.0), 1.0, 0.5),
            Surface::metallic_roughness(Vec3::new(1.0, 0.77, 0.34), 1.0, 0.5),
            Model::CookTorrance,
        ),
    ];
    let lights = test_lights();
    for (name, material, surface, model) in cases {
        let scene = sphere_scene(material, lights.clone());
        let oracle =
            brdf::render_sphere_oracle(&ocam, Vec3::ZERO, 1.0, &surface, model, &scene.lights);
        for technique in Technique::ALL {
            let img = render(
                ctx,
                &scene,
                &camera,
                SPHERE_SIZE,
                technique,
                VariantMode::Preprocess,
            );
            if technique == Technique::Deferred {
                save_rgb_review(
                    &format!("materials_oracle_{}", name.replace(' ', "_")),
                    SPHERE_SIZE,
                    &img,
                );
            }
            let (p99, mean, n) = oracle_error(&img, &oracle, SPHERE_SIZE, 0.05);
            eprintln!(
                "{name:>24} {technique:>13}: {n} px, relative error p99 {:.2} %, mean {:.3} %",
                p99 * 100.0,
                mean * 100.0
            );
            // Forward shades in f32 from interpolated normals; deferred and the
            // light pre-pass read 8-bit sRGB colours and 10-bit normals.
            let (p99_max, mean_max) = match technique {
                Technique::Forward => (0.02, 0.005),
                _ => (0.04, 0.01),
            };
            assert!(
                p99 <= p99_max && mean <= mean_max,
                "{name} ({technique}): p99 {p99}, mean {mean}"
            );
        }
    }
}

#[test]
fn gltf_metallic_roughness_spheres_follow_the_specification() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = gltf_gen::load_spheres(false);
    assert_eq!(scene.lights.len(), 1, "the file's light and no other");
    let (w, h) = (480, 192);
    let camera = gltf_gen::camera();
    let ocam = OracleCamera::of(&camera, w, h);
    for technique in [Technique::Deferred, Technique::Forward] {
        let img = render(
            ctx,
            &scene,
            &camera,
            (w, h),
            technique,
            VariantMode::Preprocess,
        );
        save_rgb_review(&format!("materials_gltf_spheres_{technique}"), (w, h), &img);
        for (i, m) in gltf_gen::SPHERE_MATERIALS.iter().enumerate() {
            let base = Vec3::new(m.base_color[0], m.base_color[1], m.base_color[2]);
            let surface = Surface::metallic_roughness(base, m.metallic, m.roughness);
            let oracle = brdf::render_sphere_oracle(
                &ocam,
                gltf_gen::SPHERE_CENTRES[i],
                gltf_gen::SPHERE_RADIUS,
                &surface,
                Model::CookTorrance,
                &scene.lights,
            );
            let (p99, mean, n) = oracle_error(&img, &oracle, (w, h), 0.05);
            eprintln!(
                "{:>18} {technique:>9}: {n} px, error vs the glTF spec p99 {:.2} %, mean {:.3} %",
                m.name,
                p99 * 100.0,
                mean * 100.0
            );
            assert!(n > 2000, "{}: sphere not in view", m.name);
            // The generator's spheres have 64 segments: interpolated normals and
            // flat facets move a smooth highlight by a few per cent at its edge.
            assert!(
                p99 <= 0.05 && mean <= 0.01,
                "{}: p99 {p99}, mean {mean}",
                m.name
            );
        }
    }
}

/// A user's surface and lighting shader, the pair `docs/materials.md` shows.
const USER_SURFACE: &str = include_str!("../docs/examples/stripes.wgsl");
const USER_LIGHTING: &str = include_str!("../docs/examples/wrap_lambert.wgsl");
const USER_MATERIALS: &str = include_str!("../docs/examples/stripes.fx");

/// A folder with the user's shaders of [`USER_MATERIALS`] in it.
fn user_shaders() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("stripes.wgsl"), USER_SURFACE).unwrap();
    std::fs::write(dir.path().join("wrap_lambert.wgsl"), USER_LIGHTING).unwrap();
    dir
}

/// Eight objects: the library's two surfaces (standard with colour and normal
/// maps, triplanar with a colour map) × four lighting shaders, plus the user pair.
fn pairs_scene() -> (Scene, tempfile::TempDir) {
    let dir = user_shaders();
    let mut scene = Scene {
        name: "pairs".into(),
        ..Default::default()
    };
    scene.meshes.push(uv_sphere(48, 24));
    scene.meshes.push(box_mesh(Vec3::ONE));
    let mut text = String::new();
    for surface in ["standard", "triplanar"] {
        for (lighting, settings) in [
            ("lambert", ""),
            ("phong", "SPECULAR_POWER = 40"),
            ("blinn_phong", "shininess = 90"),
            ("cook_torrance", ""),
        ] {
            let maps = if surface == "standard" {
                "base_color_map = \"builtin:checker\" normal_map = \"builtin:bumps\" roughness = 0.4 specular = (0.2, 0.2, 0.2)"
            } else {
                "base_color_map = \"builtin:bricks\" scale = 0.5 roughness = 0.4"
            };
            text.push_str(&format!(
                "MATERIAL.{surface}_{lighting} = {{ SURFACE = SHADER.{surface} {{ {maps} }} LIGHTING = SHADER.{lighting} {{ {settings} }} }}\n"
            ));
        }
    }
    text.push_str(USER_MATERIALS);
    let file =
        load_materials("pairs.fx", &text, Some(dir.path()), 0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.materials.len(), 9);
    scene.textures = file.textures;
    for (i, m) in file.materials.into_iter().enumerate() {
        let (x, z) = ((i % 3) as f32 * 2.4 - 2.4, (i / 3) as f32 * 2.4 - 2.4);
        scene.instances.push(Instance {
            name: m.name.clone(),
            mesh: i % 2,
            material: i,
            transform: Mat4::from_translation(Vec3::new(x, 0.0, z))
                * Mat4::from_rotation_y(0.4 + i as f32)
                * Mat4::from_scale(Vec3::splat(0.9)),
            ..Default::default()
        });
        scene.materials.push(m);
    }
    scene.lights = vec![
        Light::directional(Vec3::new(-0.4, -1.0, -0.5), Vec3::ONE, 3.0),
        Light::point(
            Vec3::new(1.0, 2.0, 2.0),
            Vec3::new(1.0, 0.6, 0.3),
            40.0,
            8.0,
        ),
        Light::spot(
            Vec3::new(-2.0, 3.0, 1.0),
            Vec3::new(0.3, -1.0, -0.2),
            Vec3::new(0.4, 0.7, 1.0),
            60.0,
            9.0,
            0.3,
            0.6,
        ),
        Light::ambient(Vec3::ONE, 0.05),
    ];
    (scene, dir)
}

#[test]
fn techniques_and_variant_modes_agree_for_every_surface_and_lighting_pair() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let (scene, _dir) = pairs_scene();
    let size = (192, 144);
    let spec = "eye=0,6,7;target=0,0,0;fov=50";
    let (camera, reference) =
        reviewed_reference(ctx, &scene, spec, size, "materials_pairs_deferred");
    assert!(
        reference
            .iter()
            .filter(|p| p[0] + p[1] + p[2] > 0.05)
            .count()
            > reference.len() / 6,
        "the scene is mostly dark"
    );
    for technique in Technique::ALL {
        let per_mode: Vec<Vec<[f32; 4]>> = VariantMode::ALL
            .iter()
            .map(|&mode| render(ctx, &scene, &camera, size, technique, mode))
            .collect();
        let preprocessed = &per_mode[0];
        assert_psnr(
            &format!("deferred vs {technique}"),
            &reference,
            preprocessed,
            40.0,
        );
        for (mode, img) in VariantMode::ALL.iter().zip(&per_mode).skip(1) {
            let what = format!("{technique}: preprocess vs {mode}");
            assert_psnr(&what, preprocessed, img, 60.0);
        }
    }
}

#[test]
fn variants_are_compiled_once_and_counted_by_mode() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = Scene::load("builtin:room").unwrap();
    let camera = scene.default_camera();
    let mut counts = Vec::new();
    for mode in VariantMode::ALL {
        let mut r = renderer(ctx, &scene, mode);
        let (_, first) = r
            .render(ctx, &camera, 64, 48, Technique::Deferred, None)
            .unwrap();
        let (_, second) = r
            .render(ctx, &camera, 64, 48, Technique::Deferred, None)
            .unwrap();
        assert_eq!(
            (second.pipelines, second.shader_modules),
            (first.pipelines, first.shader_modules),
            "{mode}: the second frame compiled again"
        );
        let set = r.materials();
        // distinct (surface, lighting) pairs and (pair, features) keys in use
        let mut pairs: Vec<(usize, usize)> = set
            .materials
            .iter()
            .map(|m| (m.surface, m.lighting))
            .collect();
        pairs.sort();
        pairs.dedup();
        eprintln!(
            "{mode}: {} pipelines, {} shader modules for {} materials ({} surface/lighting pairs)",
            first.pipelines,
            first.shader_modules,
            set.materials.len(),
            pairs.len()
        );
        counts.push((mode, first.pipelines, first.shader_modules, pairs.len()));
    }
    let (_, pre_p, pre_m, pairs) = counts[0];
    let (_, ovr_p, ovr_m, _) = counts[1];
    let (_, br_p, br_m, _) = counts[2];
    // one module per pair (+ the light module) unless preprocessing
    assert_eq!(ovr_m, pairs + 1);
    assert_eq!(br_m, pairs + 1);
    assert!(
        pre_m > pairs + 1,
        "preprocessing compiles a module per feature set"
    );
    // override and preprocess specialise the same pipelines; branching shares them
    assert_eq!(ovr_p, pre_p);
    assert!(
        br_p < pre_p,
        "branching: {br_p} pipelines, preprocess {pre_p}"
    );
}

#[test]
fn user_materials_replace_scene_materials_by_name_and_star() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let dir = user_shaders();
    let mut scene = Scene::load("builtin:room").unwrap();
    let first = scene.textures.len();
    let file = load_materials("stripes.fx", USER_MATERIALS, Some(dir.path()), first).unwrap();
    let replaced = apply_materials(
        &mut scene,
        file.clone(),
        &[("red".into(), "stripes".into())],
    )
    .unwrap();
    assert_eq!(replaced, vec!["red".to_string()]);
    let red = scene.materials.iter().find(|m| m.name == "red").unwrap();
    assert_eq!(red.surface.shader, "stripes");
    let mut all = Scene::load("builtin:room").unwrap();
    let n = all.materials.len();
    let file = load_materials(
        "stripes.fx",
        USER_MATERIALS,
        Some(dir.path()),
        all.textures.len(),
    )
    .unwrap();
    let replaced = apply_materials(&mut all, file, &[("*".into(), "stripes".into())]).unwrap();
    assert_eq!(replaced.len(), n);
    let camera = all.default_camera();
    let img = reference(ctx, &all, &camera, (96, 64));
    assert!(img.iter().any(|p| p[0] > 0.01));
    let err = apply_materials(
        &mut scene,
        Default::default(),
        &[("nope".into(), "stripes".into())],
    )
    .unwrap_err();
    assert!(err.contains("no MATERIAL.stripes"), "{err}");
}

/// The benchmark (not a test): `bash bench/materials.sh`, or
/// `cargo test --release --test scene -- --ignored materials::variant_benchmark --nocapture`.
/// builtin:bench with its materials replaced by the standard surface in nine map
/// combinations (bench/materials_maps.fx) and `FX_BENCH_LIGHTS` random point
/// lights (default 16). Environment: FX_BENCH_SIZE=WxH (1920x1080),
/// FX_BENCH_FRAMES (5), FX_BENCH_OUT=report.md.
#[test]
#[ignore]
fn variant_benchmark() {
    use common::variant_bench::run_variant_benchmark;
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let (w, h) = bench::size().unwrap_or((1920, 1080));
    let frames: usize = bench::setting("FRAMES").unwrap_or(5);
    let lights: usize = bench::setting("LIGHTS").unwrap_or(16);
    let mut scene = Scene::load("builtin:bench").unwrap();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bench");
    let text = std::fs::read_to_string(dir.join("materials_maps.fx")).unwrap();
    let file = load_materials(
        "bench/materials_maps.fx",
        &text,
        Some(&dir),
        scene.textures.len(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let replaced = apply_materials(&mut scene, file, &[]).unwrap();
    assert_eq!(replaced.len(), 9, "{replaced:?}");
    scene.add_random_point_lights_sized(lights, 4, 0.05, 0.12);
    let camera = scene.default_camera();
    let report = run_variant_benchmark(
        ctx,
        &scene,
        &camera,
        (w, h),
        &VariantMode::ALL,
        &[Technique::Forward, Technique::Deferred],
        (1, frames),
        |r| {
            eprintln!(
                "  {:>9} {:>10}: surface pass {:.1} ms, frame {:.1} ms",
                r.technique.to_string(),
                r.mode.to_string(),
                r.surface_pass_ms,
                r.frame_ms
            )
        },
    )
    .unwrap();
    bench::publish(&report);
}

/// The glTF sphere that uses every core texture, KHR_texture_transform, texture
/// coordinate set 1, vertex colours, MASK and double-sided: the three techniques
/// and the three variant modes give the same image.
#[test]
fn textured_gltf_material_agrees_across_techniques_and_modes() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let scene = gltf_gen::load_spheres(true);
    let textured = scene
        .materials
        .iter()
        .find(|m| m.name == gltf_gen::textured::NAME)
        .expect("the textured material");
    assert!(
        textured.surface.textures.len() >= 5,
        "{:?}",
        textured.surface.textures
    );
    let size = (160, 160);
    let spec = "eye=0,-1.2,7;target=0,-1.2,0;fov=55";
    let (camera, reference) =
        reviewed_reference(ctx, &scene, spec, size, "materials_gltf_textured");
    for technique in Technique::ALL {
        for mode in VariantMode::ALL {
            let img = render(ctx, &scene, &camera, size, technique, mode);
            let what = format!("textured glTF: deferred/preprocess vs {technique}/{mode}");
            assert_psnr(&what, &reference, &img, 40.0);
        }
    }
}

/// Mesh flags (here HAS_VERTEX_COLOR) follow the mesh in every mode: a surface
/// that uses the vertex colour only where the mesh has one renders alike with
/// preprocessor variants and run-time branches.
#[test]
fn mesh_flags_follow_the_mesh_in_every_mode() {
    let Some(gpu) = gpu_context() else { return };
    let ctx = &*gpu;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("vcolor.wgsl"),
        "fn surface(in: SurfaceInput) -> SurfaceOutput {\n    var c = vec3<f32>(0.2, 0.4, 0.8);\n#ifdef HAS_VERTEX_COLOR\n    c = in.color.rgb;\n#endif\n    var out: SurfaceOutput;\n    out.diffuse = c;\n    out.specular = vec3<f32>(0.04);\n    out.roughness = 0.5;\n    out.alpha = 1.0;\n    out.normal = in.normal;\n    out.emission = vec3<f32>(0.0);\n    out.occlusion = 1.0;\n    return out;\n}\n",
    )
    .unwrap();
    let file = load_materials(
        "v.fx",
        "MATERIAL.v = { SURFACE = SHADER.vcolor LIGHTING = SHADER.lambert }\n",
        Some(dir.path()),
        0,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut scene = Scene {
        name: "vertex colours".into(),
        ..Default::default()
    };
    let plain = box_mesh(Vec3::ONE);
    let mut coloured = box_mesh(Vec3::ONE);
    coloured.colors = vec![Vec4::new(1.0, 0.2, 0.1, 1.0); coloured.positions.len()];
    scene.meshes = vec![plain, coloured];
    scene.materials = file.materials;
    for (i, x) in [-0.8f32, 0.8].iter().enumerate() {
        scene.instances.push(Instance {
            name: format!("box {i}"),
            mesh: i,
            material: 0,
            transform: Mat4::from_translation(Vec3::new(*x, 0.0, 0.0)),
            ..Default::default()
        });
    }
    scene.lights = vec![Light::directional(
        Vec3::new(-0.3, -0.5, -1.0),
        Vec3::ONE,
        3.0,
    )];
    let camera = Camera::parse_spec("eye=0,0.5,4;target=0,0,0;fov=45", &scene).unwrap();
    let size = (96, 64);
    let [pre, branch] = [VariantMode::Preprocess, VariantMode::Branch]
        .map(|mode| render(ctx, &scene, &camera, size, Technique::Forward, mode));
    assert_psnr("preprocess vs branch", &pre, &branch, 60.0);
    // the two boxes differ: blue (no colours) and red (vertex colours)
    let left = pre[(32 * 96 + 24) as usize];
    let right = pre[(32 * 96 + 72) as usize];
    assert!(
        left[2] > left[0] && right[0] > right[2],
        "{left:?} {right:?}"
    );
}
