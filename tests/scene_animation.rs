//! glTF animation sampling and playback (CPU, no GPU): node translation, rotation,
//! scale and morph weights posed through the loader, compared with an oracle
//! written in this file from the glTF 2.0 specification, Appendix C
//! ("Animation Sampler Interpolation Modes") and §3.11 ("Animations": outputs
//! clamped to the ends of the input range); looping and the selection of
//! animations; the loader's errors for broken animation data; a still scene
//! poses its rest pose.
//!
//! Tolerances: positions and weights 1e-5 (relative to max(1, |v|)); rotations
//! compared as the images of the X and Y axes, 1e-5. The oracle works in f64,
//! the implementation samples in f64 from f32 keys.

use crate::common;

use common::anim_gltf::{appendix_c as oracle, node_scene, write, ChannelSpec, GltfBuilder};
use fxgraph::scene::{Playback, Scene, Selection};
use glam::{DQuat, DVec4, Mat4, Quat, Vec3};
use serde_json::{json, Value};

/// Times to sample: before, at, between and after the keys.
fn sample_times(times: &[f32]) -> Vec<f64> {
    let (first, last) = (times[0] as f64, *times.last().unwrap() as f64);
    let mut out: Vec<f64> = (0..=90)
        .map(|i| first - 0.5 + (last - first + 1.0) * i as f64 / 90.0)
        .collect();
    out.extend(times.iter().map(|&t| t as f64));
    out
}

fn close(a: &[f64], b: &[f64], what: &str) {
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x - y).abs() <= 1e-5 * x.abs().max(1.0),
            "{what}: {a:?} vs oracle {b:?}"
        );
    }
}

/// A file with one channel on node 0 (the triangle).
fn one_channel(path: &str, interp: &str, times: &[f32], values: &[f32]) -> Scene {
    load(channel_doc(0, path, interp, times, values))
}

fn load(doc: Value) -> Scene {
    let (_dir, path) = write(&doc, "anim.gltf");
    Scene::load(path.to_str().unwrap()).unwrap()
}

fn load_err(doc: Value) -> String {
    let (_dir, path) = write(&doc, "broken_anim.gltf");
    match Scene::load(path.to_str().unwrap()) {
        Ok(_) => panic!("the file was accepted"),
        Err(e) => e.to_string(),
    }
}

const TIMES: [f32; 4] = [0.5, 1.0, 2.25, 3.0];

/// Translation keys (per key: in-tangent, value, out-tangent when `cubic`).
fn vec3_keys(cubic: bool) -> Vec<f32> {
    let values = [
        [0.0, 1.0, -2.0],
        [3.0, -1.0, 0.5],
        [-2.0, 4.0, 1.0],
        [1.0, 1.0, 1.0],
    ];
    let tangents_in = [
        [9.0, 9.0, 9.0],
        [1.0, -2.0, 0.5],
        [-3.0, 0.0, 2.0],
        [0.5, 0.5, -1.0],
    ];
    let tangents_out = [
        [2.0, 1.0, -1.0],
        [-1.0, 3.0, 0.0],
        [0.0, -2.0, 4.0],
        [9.0, 9.0, 9.0],
    ];
    (0..4)
        .flat_map(|k| {
            if cubic {
                [tangents_in[k], values[k], tangents_out[k]].concat()
            } else {
                values[k].to_vec()
            }
        })
        .collect()
}

#[test]
fn translation_follows_appendix_c_in_every_mode() {
    for interp in ["STEP", "LINEAR", "CUBICSPLINE"] {
        let keys = vec3_keys(interp == "CUBICSPLINE");
        let scene = one_channel("translation", interp, &TIMES, &keys);
        assert!(scene.is_animated());
        assert_eq!(scene.animation_duration(&Playback::default()), 3.0);
        for tc in sample_times(&TIMES) {
            let pose = scene.pose(tc, &Playback::default());
            let got = pose.instances[0]
                .world
                .w_axis
                .truncate()
                .as_dvec3()
                .to_array();
            let want = oracle(interp, &TIMES, &keys, 3, false, tc);
            close(&got, &want, &format!("{interp} translation at {tc}"));
        }
    }
}

#[test]
fn scale_follows_appendix_c() {
    for interp in ["STEP", "LINEAR", "CUBICSPLINE"] {
        let keys: Vec<f32> = vec3_keys(interp == "CUBICSPLINE")
            .iter()
            .map(|v| v.abs() + 0.5)
            .collect();
        let scene = one_channel("scale", interp, &TIMES, &keys);
        for tc in sample_times(&TIMES) {
            let w = scene.pose(tc, &Playback::default()).instances[0].world;
            let got = [w.x_axis.x as f64, w.y_axis.y as f64, w.z_axis.z as f64];
            let want = oracle(interp, &TIMES, &keys, 3, false, tc);
            close(&got, &want, &format!("{interp} scale at {tc}"));
        }
    }
}

/// Compares a world matrix's rotation with a quaternion by the images of X and Y.
fn same_rotation(world: Mat4, q: [f64; 4], what: &str) {
    let q = DQuat::from_xyzw(q[0], q[1], q[2], q[3]);
    for axis in [Vec3::X, Vec3::Y] {
        let got = world.transform_vector3(axis).as_dvec3();
        let want = q * axis.as_dvec3();
        assert!(
            (got - want).length() < 1e-5,
            "{what}: {got} vs oracle {want}"
        );
    }
}

#[test]
fn rotation_slerps_on_the_shortest_arc() {
    // Four keys; keys 1 and 2 have a negative dot product (key 2 is stored
    // negated), so the shortest arc needs the sign flip of Appendix C.
    let q = [
        Quat::from_rotation_z(0.2),
        Quat::from_rotation_y(1.1) * Quat::from_rotation_x(0.3),
        -Quat::from_rotation_x(2.5),
        Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), -0.8),
    ];
    let dot = DVec4::from(q[1].to_array().map(f64::from))
        .dot(DVec4::from(q[2].to_array().map(f64::from)));
    assert!(
        dot < 0.0,
        "the test needs a pair with a negative dot product"
    );
    let keys: Vec<f32> = q.iter().flat_map(|q| q.to_array()).collect();
    for interp in ["STEP", "LINEAR"] {
        let scene = one_channel("rotation", interp, &TIMES, &keys);
        for tc in sample_times(&TIMES) {
            let world = scene.pose(tc, &Playback::default()).instances[0].world;
            let want = oracle(interp, &TIMES, &keys, 4, true, tc);
            same_rotation(
                world,
                [want[0], want[1], want[2], want[3]],
                &format!("{interp} at {tc}"),
            );
        }
    }
    // Halfway between 0° and a key of 90° stored as its negative: 45°, not 225°.
    let a = Quat::IDENTITY;
    let b = -Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let keys: Vec<f32> = [a, b].iter().flat_map(|q| q.to_array()).collect();
    let scene = one_channel("rotation", "LINEAR", &[0.0, 1.0], &keys);
    let world = scene.pose(0.5, &Playback::default()).instances[0].world;
    let half = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4);
    same_rotation(world, half.to_array(), "short arc");
}

#[test]
fn cubic_spline_rotation_is_normalised() {
    let values = [
        Quat::from_rotation_z(0.1),
        Quat::from_rotation_x(0.9) * Quat::from_rotation_z(0.4),
        Quat::from_rotation_y(-0.7),
        Quat::from_rotation_z(1.5),
    ];
    let tangent = |k: usize| [0.3 * k as f32, -0.2, 0.5, 0.1 * k as f32];
    let keys: Vec<f32> = (0..4)
        .flat_map(|k| [tangent(k), values[k].to_array(), tangent(k + 1)].concat())
        .collect();
    let scene = one_channel("rotation", "CUBICSPLINE", &TIMES, &keys);
    for tc in sample_times(&TIMES) {
        let world = scene.pose(tc, &Playback::default()).instances[0].world;
        let want = oracle("CUBICSPLINE", &TIMES, &keys, 4, true, tc);
        same_rotation(
            world,
            [want[0], want[1], want[2], want[3]],
            &format!("cubic at {tc}"),
        );
    }
}

/// A triangle with two POSITION morph targets and a `weights` channel.
fn morph_scene(interp: &str, times: &[f32], values: &[f32]) -> Scene {
    let mut b = GltfBuilder::default();
    let t0 = b.f32s(&[0.0, 1.0, 0.0].repeat(3), "VEC3");
    let t1 = b.f32s(&[1.0, 0.0, 0.0].repeat(3), "VEC3");
    let mut doc = node_scene(
        &mut b,
        json!({}),
        Some(json!([{"POSITION": t0}, {"POSITION": t1}])),
        vec![],
        &[],
        &[vec![ChannelSpec {
            node: 0,
            path: "weights",
            interpolation: interp,
            times,
            values,
        }]],
    );
    doc["meshes"][0]["weights"] = json!([0.25, 0.5]);
    load(b.finish(doc))
}

#[test]
fn morph_weights_follow_appendix_c() {
    for interp in ["STEP", "LINEAR", "CUBICSPLINE"] {
        // two targets per element
        let keys: Vec<f32> = if interp == "CUBICSPLINE" {
            (0..4)
                .flat_map(|k| {
                    let k = k as f32;
                    [0.5 * k, -0.25, 0.1 * k, 1.0 - 0.2 * k, -0.3, 0.7 * k]
                })
                .collect()
        } else {
            vec![0.0, 1.0, 0.5, 0.25, 1.0, 0.0, 0.2, 0.8]
        };
        let scene = morph_scene(interp, &TIMES, &keys);
        assert_eq!(scene.instances[0].morph_weights, vec![0.25, 0.5]);
        assert_eq!(
            scene.rest_pose().instances[0].morph_weights,
            vec![0.25, 0.5],
            "the rest pose has the mesh's default weights"
        );
        for tc in sample_times(&TIMES) {
            let pose = scene.pose(tc, &Playback::default());
            let got: Vec<f64> = pose.instances[0]
                .morph_weights
                .iter()
                .map(|&w| w as f64)
                .collect();
            let want = oracle(interp, &TIMES, &keys, 2, false, tc);
            close(&got, &want, &format!("{interp} weights at {tc}"));
            // and the vertices move by Σ wᵢ Δᵢ (targets +Y and +X)
            let posed = pose.skinned_mesh(&scene, 0).positions;
            let d = Vec3::new(want[1] as f32, want[0] as f32, 0.0);
            for (p, rest) in posed.iter().zip(common::anim_gltf::TRIANGLE) {
                assert!((*p - (rest + d)).length() < 1e-5, "{p} vs {}", rest + d);
            }
        }
    }
}

#[test]
fn looping_wraps_the_clock_and_holding_clamps_it() {
    let keys = vec3_keys(false);
    let scene = one_channel("translation", "LINEAR", &TIMES, &keys);
    let hold = Playback::default();
    let looping = Playback {
        looping: true,
        ..hold
    };
    let at = |t: f64, p: &Playback| scene.pose(t, p).instances[0].world.w_axis.truncate();
    // holding: before the first key the first value, after the last the last
    assert_eq!(at(-3.0, &hold), Vec3::new(0.0, 1.0, -2.0));
    assert_eq!(at(0.0, &hold), Vec3::new(0.0, 1.0, -2.0));
    assert_eq!(at(100.0, &hold), Vec3::new(1.0, 1.0, 1.0));
    // looping with period 3 s (the last key)
    for t in [0.2, 0.75, 1.6, 2.9] {
        let want = at(t, &hold);
        for k in [-2.0, 1.0, 5.0] {
            let got = at(t + 3.0 * k, &looping);
            assert!(
                (got - want).length() < 1e-4,
                "t {t} + {k} periods: {got} vs {want}"
            );
        }
    }
    assert_eq!(scene.pose(7.5, &looping).time, 1.5);
}

/// Two animations: `anim0` moves node 0 over 2 s, `anim1` turns node 1 over 4 s.
fn two_animations() -> Scene {
    let mut b = GltfBuilder::default();
    let turn: Vec<f32> = [Quat::IDENTITY, Quat::from_rotation_y(1.0)]
        .iter()
        .flat_map(|q| q.to_array())
        .collect();
    let doc = node_scene(
        &mut b,
        json!({}),
        None,
        vec![json!({"name": "spinner", "translation": [0.0, 2.0, 0.0]})],
        &[1],
        &[
            vec![ChannelSpec {
                node: 0,
                path: "translation",
                interpolation: "LINEAR",
                times: &[0.0, 2.0],
                values: &[0.0, 0.0, 0.0, 4.0, 0.0, 0.0],
            }],
            vec![ChannelSpec {
                node: 1,
                path: "rotation",
                interpolation: "LINEAR",
                times: &[0.0, 4.0],
                values: &turn,
            }],
        ],
    );
    load(b.finish(doc))
}

#[test]
fn all_animations_play_on_one_clock() {
    let scene = two_animations();
    let all = Playback::default();
    assert_eq!(scene.animation_duration(&all), 4.0);
    let pose = scene.pose(1.0, &all);
    assert_eq!(pose.nodes[0].w_axis.x, 2.0);
    let spin = pose.nodes[1].transform_vector3(Vec3::X);
    assert!((spin - Quat::from_rotation_y(0.25) * Vec3::X).length() < 1e-6);
    assert_eq!(
        pose.nodes[1].w_axis.y, 2.0,
        "untouched TRS parts keep their rest value"
    );
    let only1 = Playback::parse("anim1", &scene, false).unwrap();
    assert_eq!(only1.selection, Selection::One(1));
    assert_eq!(scene.animation_duration(&only1), 4.0);
    let pose = scene.pose(1.0, &only1);
    assert_eq!(pose.nodes[0].w_axis.x, 0.0, "anim0 does not play");
    let none = Playback::parse("none", &scene, true).unwrap();
    assert_eq!(scene.animation_duration(&none), 0.0);
    let (still, rest) = (scene.pose(1.0, &none), scene.rest_pose());
    assert_eq!((still.nodes, still.instances), (rest.nodes, rest.instances));
    // looping `all` wraps at the longest duration
    let looping = Playback::parse("ALL", &scene, true).unwrap();
    assert_eq!(scene.pose(5.0, &looping).nodes[0].w_axis.x, 2.0);
}

#[test]
fn playback_parse_accepts_names_indices_and_keywords() {
    let scene = two_animations();
    let p = |s: &str| Playback::parse(s, &scene, false).map(|p| p.selection);
    assert_eq!(p("all").unwrap(), Selection::All);
    assert_eq!(p(" None ").unwrap(), Selection::None);
    assert_eq!(p("0").unwrap(), Selection::One(0));
    assert_eq!(p("anim1").unwrap(), Selection::One(1));
    for bad in ["2", "walk"] {
        let e = p(bad).unwrap_err().to_string();
        assert!(e.contains(&format!("animation `{bad}`")), "{e}");
        assert!(
            e.contains("0 `anim0`, 1 `anim1`"),
            "the error lists the animations: {e}"
        );
    }
    let still = Scene::load("builtin:room").unwrap();
    let e = Playback::parse("0", &still, false).unwrap_err().to_string();
    assert!(e.contains("has no animations"), "{e}");
}

/// A one-channel document for the error tests.
fn channel_doc(node: usize, path: &str, interp: &str, times: &[f32], values: &[f32]) -> Value {
    let mut b = GltfBuilder::default();
    let doc = node_scene(
        &mut b,
        json!({}),
        None,
        vec![],
        &[],
        &[vec![ChannelSpec {
            node,
            path,
            interpolation: interp,
            times,
            values,
        }]],
    );
    b.finish(doc)
}

/// node, path, interpolation, times, values, expected message
type BrokenChannel<'a> = (usize, &'a str, &'a str, &'a [f32], &'a [f32], &'a str);

#[test]
fn broken_channels_are_clear_errors() {
    let t3 = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let t6 = [&t3[..], &[2.0; 3]].concat();
    let cases: [BrokenChannel; 9] = [
        (
            7,
            "translation",
            "LINEAR",
            &[0.0, 1.0],
            &t3,
            "node 7 does not exist",
        ),
        (
            0,
            "translation",
            "LINEAR",
            &[0.0, 2.0, 1.0],
            &t6,
            "not strictly increasing: key 2 at 1 s follows key 1 at 2 s",
        ),
        (
            0,
            "translation",
            "LINEAR",
            &[0.0, 1.0, 1.0],
            &t6,
            "not strictly increasing",
        ),
        (
            0,
            "translation",
            "LINEAR",
            &[0.0, f32::NAN],
            &t3,
            "key time 1 is NaN",
        ),
        (
            0,
            "translation",
            "LINEAR",
            &[0.0, 1.0],
            &[0.0, f32::NAN, 0.0, 1.0, 1.0, 1.0],
            "value 1 of key 0 is NaN",
        ),
        (
            0,
            "translation",
            "CUBICSPLINE",
            &[0.0, 1.0],
            &t3,
            "6 values for 2 keys (18 expected",
        ),
        (
            0,
            "rotation",
            "LINEAR",
            &[0.0, 1.0],
            &[0.0; 8],
            "rotation key 0 is the zero quaternion",
        ),
        (
            0,
            "traNslation",
            "LINEAR",
            &[0.0, 1.0],
            &t3,
            "the target path is not translation, rotation, scale or weights",
        ),
        (
            0,
            "weights",
            "LINEAR",
            &[0.0, 1.0],
            &[0.0, 1.0],
            "no mesh with morph targets",
        ),
    ];
    for (node, path, interp, times, values, expected) in cases {
        let e = load_err(channel_doc(node, path, interp, times, values));
        assert!(e.contains("broken_anim.gltf: "), "names the file: {e}");
        assert!(
            e.contains("animation 0 (`anim0`) channel 0"),
            "names the channel: {e}"
        );
        assert!(e.contains(expected), "{path} {times:?}: {e}");
    }
}

#[test]
fn a_skin_over_the_joint_limit_is_refused() {
    let mut b = GltfBuilder::default();
    let joints = fxgraph::scene::MAX_JOINTS + 1;
    let extra: Vec<Value> = (0..joints)
        .map(|i| json!({"name": format!("j{i}")}))
        .collect();
    let mut doc = node_scene(&mut b, json!({}), None, extra, &[], &[]);
    doc["skins"] = json!([{"name": "big", "joints": (1..=joints).collect::<Vec<_>>()}]);
    let e = load_err(b.finish(doc));
    assert!(
        e.contains("skin 0 (`big`): 257 joints, at most 256 are supported"),
        "{e}"
    );
}

#[test]
fn a_still_scene_poses_its_rest_pose() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::gltf_gen::write_spheres_gltf(dir.path());
    let scene = Scene::load(path.to_str().unwrap()).unwrap();
    assert!(!scene.is_animated());
    assert!(!scene.nodes.is_empty() && scene.instances.iter().all(|i| i.node.is_some()));
    assert!(scene.cameras[0].node.is_some() && scene.lights[0].node.is_some());
    for builtin in [scene, Scene::load("builtin:room").unwrap()] {
        assert_eq!(builtin.animation_duration(&Playback::default()), 0.0);
        for t in [0.0, 1.5, -2.0] {
            let pose = builtin.pose(t, &Playback::default());
            for (inst, p) in builtin.instances.iter().zip(&pose.instances) {
                assert_eq!(p.world, inst.transform, "{}", inst.name);
                assert!(p.joint_matrices.is_empty() && p.morph_weights.is_empty());
            }
            assert_eq!(pose.lights, builtin.lights);
            assert_eq!(pose.cameras, builtin.cameras);
        }
    }
}
