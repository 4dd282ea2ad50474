//! GPU skinning and morph targets (src/render/upload/skinning.rs) against the CPU
//! reference `Pose::deformed_mesh` (src/scene/animation/skin.rs, itself tested
//! against the glTF specification in tests/scene_skinning.rs): the vertices the
//! compute pass wrote are read back after a frame and compared, now and one
//! frame earlier (the motion vectors' previous positions).
//!
//! Models: the corpus's RiggedSimple (2 joints, 4 influences, 160 vertices) and
//! SimpleMorph (2 position targets, no normals: a flat-shaded mesh whose face
//! normals are recomputed), the hand-built triangle of tests/scene_skinning.rs
//! with 4 and with 8 influences (normals, tangents, a morph target displacing all
//! three, on top of the skin), and a skin of `MAX_JOINTS` (256) joints, the
//! documented limit.
//!
//! Tolerances (f32 on both sides, different operation order): positions within
//! 1e-4 × max(1, |p|), unit normals and tangents within 1e-4, handedness exact.

use crate::common;

use common::anim_gltf::animated_corpus;
use common::skinned_scene::skinned_scene;
use fxgraph::render::{FrameMotion, Renderer, RendererOptions, Technique};
use fxgraph::scene::{
    Camera, Instance, Mesh, Node, NodeTransform, Playback, Pose, Scene, Skin, MAX_JOINTS,
};
use glam::{Mat4, Quat, Vec3, Vec4};

const DT: f64 = 1.0 / 30.0;

fn camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 1.0, 6.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 50f32.to_radians(),
        near: 0.1,
        far: 100.0,
    }
}

/// Largest errors seen: positions (relative to max(1, |p|)), normals, tangents.
#[derive(Debug, Default)]
struct Errors {
    position: f32,
    normal: f32,
    tangent: f32,
    vertices: usize,
}

/// Renders `scene` at each of `times` (a frame of a sequence: the pose now and
/// `DT` earlier) and compares the GPU's deformed vertices with the CPU's.
fn compare(scene: &Scene, times: &[f64]) -> Errors {
    let ctx = common::gpu_context().expect("GPU tests need an adapter (FX_REQUIRE_GPU)");
    let mut r = Renderer::new(&ctx, scene, &RendererOptions::default()).unwrap();
    let playback = Playback::default();
    let deformed = (0..scene.instances.len())
        .filter(|&i| scene.is_deformed(i))
        .count();
    assert!(deformed > 0, "{}: nothing is deformed", scene.name);
    let mut e = Errors::default();
    for &t in times {
        let (now, prev) = (scene.pose(t, &playback), scene.pose(t - DT, &playback));
        let motion = FrameMotion::posed(scene, &now, &prev);
        r.render_frame(&ctx, &camera(), &motion, 32, 32, Technique::Deferred, None)
            .unwrap();
        let got = r.deformed_vertices(&ctx, scene).unwrap();
        assert_eq!(got.len(), deformed);
        for d in got {
            accumulate(&mut e, scene, &now, &prev, &d, t);
        }
    }
    e
}

fn accumulate(
    e: &mut Errors,
    scene: &Scene,
    now: &Pose,
    prev: &Pose,
    d: &fxgraph::render::DeformedVertices,
    t: f64,
) {
    let want = now.deformed_mesh(scene, d.instance);
    let want_prev = prev.deformed_mesh(scene, d.instance);
    assert_eq!(d.now.positions.len(), want.positions.len());
    let rel = |a: Vec3, b: Vec3| (a - b).abs().max_element() / b.length().max(1.0);
    for (v, (g, w)) in d.now.positions.iter().zip(&want.positions).enumerate() {
        let err = rel(*g, *w);
        assert!(err <= 1e-4, "t {t}, vertex {v}: GPU {g} CPU {w}");
        e.position = e.position.max(err);
    }
    for (v, (g, w)) in d
        .prev_positions
        .iter()
        .zip(&want_prev.positions)
        .enumerate()
    {
        let err = rel(*g, *w);
        assert!(err <= 1e-4, "t {t} (previous), vertex {v}: GPU {g} CPU {w}");
        e.position = e.position.max(err);
    }
    for (v, (g, w)) in d.now.normals.iter().zip(&want.normals).enumerate() {
        let err = (*g - *w).abs().max_element();
        assert!(err <= 1e-4, "t {t}, normal {v}: GPU {g} CPU {w}");
        e.normal = e.normal.max(err);
    }
    assert_eq!(d.now.tangents.is_some(), want.tangents.is_some());
    if let (Some(gt), Some(wt)) = (&d.now.tangents, &want.tangents) {
        for (v, (g, w)) in gt.iter().zip(wt).enumerate() {
            let err = (g.truncate() - w.truncate()).abs().max_element();
            assert!(
                err <= 1e-4 && g.w == w.w,
                "t {t}, tangent {v}: GPU {g} CPU {w}"
            );
            e.tangent = e.tangent.max(err);
        }
    }
    e.vertices += want.positions.len();
}

#[test]
fn rigged_simple_skins_on_the_gpu_as_on_the_cpu() {
    let scene = Scene::load(animated_corpus("RiggedSimple").to_str().unwrap()).unwrap();
    let e = compare(&scene, &[0.0, 0.5, 1.1, 1.9]);
    eprintln!("RiggedSimple: {e:?}");
}

#[test]
fn simple_morph_morphs_on_the_gpu_as_on_the_cpu() {
    let scene = Scene::load(animated_corpus("SimpleMorph").to_str().unwrap()).unwrap();
    assert!(
        scene.meshes.iter().any(|m| m.flat),
        "SimpleMorph has no normals"
    );
    let e = compare(&scene, &[0.0, 1.3, 2.5, 3.9]);
    eprintln!("SimpleMorph: {e:?}");
}

#[test]
fn eight_influences_normals_and_tangents_on_the_gpu_as_on_the_cpu() {
    for eight in [false, true] {
        let scene = skinned_scene(eight);
        assert!(scene.meshes.iter().all(|m| m.tangents.is_some()));
        let e = compare(&scene, &[0.0, 0.3, 0.7, 1.0]);
        eprintln!("hand-built triangle, 8 influences {eight}: {e:?}");
    }
}

/// A strip of `MAX_JOINTS` joints (the documented limit), each a root node
/// turned and moved by its index; vertex k follows joints k and 255 − k.
fn many_joints() -> Scene {
    let n = MAX_JOINTS;
    let nodes: Vec<Node> = (0..n)
        .map(|k| {
            let a = k as f32 / n as f32;
            Node {
                name: format!("joint{k}"),
                rest: NodeTransform::Trs {
                    translation: Vec3::new(a, 2.0 * a * a, 0.5),
                    rotation: Quat::from_rotation_y(3.0 * a),
                    scale: Vec3::splat(1.0 + a),
                },
                ..Default::default()
            }
        })
        .collect();
    let positions: Vec<Vec3> = (0..n)
        .map(|k| Vec3::new((k % 16) as f32 * 0.1, (k / 16) as f32 * 0.1, 0.0))
        .collect();
    let indices: Vec<u32> = (0..n as u32 - 2).flat_map(|k| [k, k + 1, k + 2]).collect();
    let mesh = Mesh {
        name: "strip".into(),
        normals: vec![Vec3::Z; n],
        uvs: vec![glam::Vec2::ZERO; n],
        tangents: Some(vec![Vec4::new(1.0, 0.0, 0.0, 1.0); n]),
        joints: (0..n)
            .map(|k| [k as u16, (n - 1 - k) as u16, 0, 0])
            .collect(),
        weights: vec![Vec4::new(0.75, 0.25, 0.0, 0.0); n],
        positions,
        indices,
        ..Default::default()
    };
    let mut scene = Scene {
        name: "256 joints".into(),
        meshes: vec![mesh],
        materials: vec![fxgraph::scene::Material::phong(
            "strip",
            Vec3::new(0.8, 0.5, 0.3),
            0.2,
            16.0,
        )],
        instances: vec![Instance {
            name: "strip".into(),
            transform: Mat4::IDENTITY,
            skin: Some(0),
            ..Default::default()
        }],
        nodes,
        skins: vec![Skin {
            name: "many".into(),
            joints: (0..n).collect(),
            inverse_bind_matrices: (0..n)
                .map(|k| Mat4::from_rotation_x(k as f32 * 0.01))
                .collect(),
            skeleton: None,
        }],
        ..Default::default()
    };
    scene.ensure_lights();
    scene
}

#[test]
fn a_skin_of_the_joint_limit_skins_on_the_gpu_as_on_the_cpu() {
    let scene = many_joints();
    let e = compare(&scene, &[0.0]);
    eprintln!("{} joints: {e:?}", MAX_JOINTS);
}

/// A still frame after an animated one draws the mesh at rest again, and a
/// pose that does not fit the skin is a clear error.
#[test]
fn still_frames_restore_the_rest_pose_and_wrong_poses_are_refused() {
    let scene = Scene::load(animated_corpus("RiggedSimple").to_str().unwrap()).unwrap();
    let ctx = common::gpu_context().expect("GPU tests need an adapter (FX_REQUIRE_GPU)");
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let playback = Playback::default();
    let (now, prev) = (scene.pose(1.0, &playback), scene.pose(1.0 - DT, &playback));
    let motion = FrameMotion::posed(&scene, &now, &prev);
    r.render_frame(&ctx, &camera(), &motion, 32, 32, Technique::Forward, None)
        .unwrap();
    r.render(&ctx, &camera(), 32, 32, Technique::Forward, None)
        .unwrap();
    for d in r.deformed_vertices(&ctx, &scene).unwrap() {
        let rest = &scene.meshes[scene.instances[d.instance].mesh];
        for (g, w) in d.now.positions.iter().zip(&rest.positions) {
            assert!((*g - *w).abs().max_element() <= 1e-5, "GPU {g} rest {w}");
        }
        assert_eq!(d.prev_positions, d.now.positions);
    }
    let mut wrong = motion.clone();
    wrong.deformed[0].joint_matrices.pop();
    let err = r
        .render_frame(&ctx, &camera(), &wrong, 32, 32, Technique::Forward, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("1 joint matrices for a skin of 2 joints"),
        "{err}"
    );
    let mut missing = motion;
    missing.prev_deformed.clear();
    let err = r
        .render_frame(&ctx, &camera(), &missing, 32, 32, Technique::Forward, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("deformed instances"), "{err}");
}

/// The three techniques agree on an animated skinned scene (RiggedSimple at
/// t = 1.1 s, posed and deformed on the GPU, with its motion vectors), as they do
/// on still scenes (tests/deferred.rs): PSNR of the image over RGB clamped to
/// [0, 1] at least 40 dB against the deferred one, and `AUX.motion` within
/// 0.01 px. The posed image differs from the rest pose's (the animation shows).
#[test]
fn the_three_techniques_agree_on_an_animated_skinned_scene() {
    use common::renders::{rgb_psnr, save_rgb_review};
    use fxgraph::render::gbuffer::read_rgba_f32;
    use fxgraph::scene::CameraPath;
    let scene = Scene::load(animated_corpus("RiggedSimple").to_str().unwrap()).unwrap();
    let ctx = common::gpu_context().expect("GPU tests need an adapter (FX_REQUIRE_GPU)");
    let (w, h) = (160, 120);
    let playback = Playback::default();
    let t = 1.1;
    let (now, prev) = (scene.pose(t, &playback), scene.pose(t - DT, &playback));
    let path = CameraPath::parse(Some("orbit:period=4,elevation=15"), &scene).unwrap();
    let camera = path.at(&scene, Some(&now), t);
    let motion = FrameMotion {
        prev_camera: Some(path.at(&scene, Some(&prev), t - DT)),
        ..FrameMotion::posed(&scene, &now, &prev)
    };
    let mut r = Renderer::new(&ctx, &scene, &RendererOptions::default()).unwrap();
    let mut images = Vec::new();
    for technique in Technique::ALL {
        let (out, _) = r
            .render_frame(&ctx, &camera, &motion, w, h, technique, None)
            .unwrap();
        let image = read_rgba_f32(&ctx, &out.scene).unwrap();
        let vectors = read_rgba_f32(&ctx, out.aux("motion").expect("AUX.motion")).unwrap();
        save_rgb_review(&format!("skinned_{technique}"), (w, h), &image);
        images.push((technique, image, vectors));
    }
    let (_, reference, ref_motion) = &images[0];
    let moving = ref_motion
        .iter()
        .filter(|m| m[0] != 0.0 || m[1] != 0.0)
        .count();
    assert!(moving > 100, "{moving} pixels move");
    for (technique, image, vectors) in &images[1..] {
        let p = rgb_psnr(reference, image, true);
        let dm = vectors
            .iter()
            .zip(ref_motion)
            .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()))
            .fold(0.0f32, f32::max);
        eprintln!("deferred vs {technique}: PSNR {p:.2} dB, motion max |diff| {dm} px");
        assert!(p >= 40.0, "deferred vs {technique}: {p:.2} dB");
        assert!(
            dm <= 0.01,
            "deferred vs {technique}: motion differs by {dm} px"
        );
    }
    let (rest, _) = r
        .render(&ctx, &camera, w, h, Technique::Deferred, None)
        .unwrap();
    let rest = read_rgba_f32(&ctx, &rest.scene).unwrap();
    let p = rgb_psnr(reference, &rest, true);
    assert!(
        p < 40.0,
        "the posed image equals the rest pose's ({p:.2} dB)"
    );
}
