//! The animated glTF sample models of the corpus (../shared/corpus/gltf/animated:
//! AnimatedTriangle, BoxAnimated, SimpleSkin, RiggedSimple, SimpleMorph; see its
//! README.md) load and animate as the specification says. The reference is
//! computed in this file from the files read independently of fxgraph's loader
//! (JSON + base64 buffers, `common::anim_gltf::RawGltf`): every channel sampled
//! with the Appendix C oracle, node globals as parent · local (§3.5.3), joint
//! matrices `inverse(global(mesh node)) · global(joint) · inverseBind` and skinned
//! vertices `Σ wₖ · global(jointₖ) · inverseBindₖ · p` (§3.7.3, weights
//! renormalised to sum 1), morphed vertices `p + Σ wᵢ Δᵢ` (§3.7.2.2).
//!
//! A missing corpus fails the tests with a message. Tolerance: 1e-4 relative to
//! max(1, the largest magnitude compared).

use crate::common;

use common::anim_gltf::{animated_corpus, appendix_c, RawGltf};
use fxgraph::scene::{Playback, Scene};
use glam::{Mat4, Quat, Vec3};

/// One channel of the file as read from the JSON and buffers.
struct RawChannel {
    node: usize,
    path: String,
    interpolation: String,
    times: Vec<f32>,
    values: Vec<f32>,
}

fn raw_channels(raw: &RawGltf) -> Vec<RawChannel> {
    let mut out = Vec::new();
    for anim in raw.json["animations"].as_array().unwrap() {
        for ch in anim["channels"].as_array().unwrap() {
            let sampler = &anim["samplers"][ch["sampler"].as_u64().unwrap() as usize];
            let acc = |key: &str| raw.accessor(sampler[key].as_u64().unwrap() as usize);
            let path = ch["target"]["path"].as_str().unwrap().to_string();
            let interpolation = sampler["interpolation"].as_str().unwrap_or("LINEAR");
            let mut values: Vec<Vec<f32>> = acc("output");
            if path == "rotation" {
                // Rotation keys are unit quaternions up to the file's rounding
                // (AnimatedTriangle stores 0.707 for √½): the rotation meant is
                // the normalised key. (The corpus has no CUBICSPLINE, whose
                // tangents must stay as they are.)
                assert_ne!(interpolation, "CUBICSPLINE");
                for q in &mut values {
                    let len = q.iter().map(|c| c * c).sum::<f32>().sqrt();
                    q.iter_mut().for_each(|c| *c /= len);
                }
            }
            out.push(RawChannel {
                node: ch["target"]["node"].as_u64().unwrap() as usize,
                path,
                interpolation: interpolation.to_string(),
                times: acc("input").into_iter().map(|r| r[0]).collect(),
                values: values.into_iter().flatten().collect(),
            });
        }
    }
    out
}

/// The reference at time `t`: node globals and, per node, its morph weights.
struct Reference {
    globals: Vec<Mat4>,
    weights: Vec<Option<Vec<f32>>>,
}

fn reference(raw: &RawGltf, channels: &[RawChannel], t: f64) -> Reference {
    let n = raw.json["nodes"].as_array().unwrap().len();
    let mut locals: Vec<Mat4> = (0..n).map(|i| raw.local(i)).collect();
    let mut weights: Vec<Option<Vec<f32>>> = vec![None; n];
    for node in 0..n {
        let mine: Vec<&RawChannel> = channels.iter().filter(|c| c.node == node).collect();
        if mine.is_empty() {
            continue;
        }
        let (mut tr, mut rot, mut sc) = raw.trs(node);
        for c in mine {
            let per_key = if c.interpolation == "CUBICSPLINE" {
                3
            } else {
                1
            };
            let width = c.values.len() / (c.times.len() * per_key);
            let rotation = c.path == "rotation";
            let v: Vec<f32> = appendix_c(&c.interpolation, &c.times, &c.values, width, rotation, t)
                .into_iter()
                .map(|x| x as f32)
                .collect();
            match c.path.as_str() {
                "translation" => tr = Vec3::from_slice(&v),
                "rotation" => rot = Quat::from_slice(&v),
                "scale" => sc = Vec3::from_slice(&v),
                "weights" => weights[node] = Some(v),
                other => panic!("path {other}"),
            }
        }
        locals[node] = Mat4::from_translation(tr) * Mat4::from_quat(rot) * Mat4::from_scale(sc);
    }
    let globals = (0..n).map(|i| raw.global(i, &|j| locals[j])).collect();
    Reference { globals, weights }
}

fn near_mat(a: Mat4, b: Mat4, what: &str) {
    let scale = b.to_cols_array().iter().fold(1.0f32, |m, v| m.max(v.abs()));
    assert!(
        a.abs_diff_eq(b, 1e-4 * scale),
        "{what}:\n{a}\nvs reference\n{b}"
    );
}

fn near_vec(a: Vec3, b: Vec3, what: &str) {
    assert!(
        (a - b).length() <= 1e-4 * b.length().max(1.0),
        "{what}: {a} vs reference {b}"
    );
}

/// Checks every node, joint matrix, morph weight and deformed vertex of `name`
/// at times around and between all keys; returns the loaded scene.
fn check_model(name: &str) -> Scene {
    let path = animated_corpus(name);
    let scene = Scene::load(path.to_str().unwrap()).unwrap();
    let raw = RawGltf::read(&path);
    let channels = raw_channels(&raw);
    assert!(scene.is_animated(), "{name}");
    let last = channels
        .iter()
        .map(|c| *c.times.last().unwrap() as f64)
        .fold(0.0, f64::max);
    assert!(
        (scene.animation_duration(&Playback::default()) - last).abs() < 1e-9,
        "{name}"
    );
    let mut times: Vec<f64> = vec![-1.0, 0.0, last + 1.0];
    for c in &channels {
        for w in c.times.windows(2) {
            times.extend([w[0] as f64, (w[0] as f64 + w[1] as f64) / 2.0, w[1] as f64]);
        }
    }
    for &t in &times {
        let pose = scene.pose(t, &Playback::default());
        let r = reference(&raw, &channels, t);
        for (i, g) in r.globals.iter().enumerate() {
            near_mat(pose.nodes[i], *g, &format!("{name} t {t}: node {i}"));
        }
        for (ii, inst) in scene.instances.iter().enumerate() {
            let node = inst.node.expect("glTF instances have nodes");
            let what = format!("{name} t {t}: instance {}", inst.name);
            let p = &pose.instances[ii];
            near_mat(p.world, r.globals[node], &what);
            let node_json = &raw.json["nodes"][node];
            let mesh_json = &raw.json["meshes"][node_json["mesh"].as_u64().unwrap() as usize];
            let prim_index: usize = inst.name.rsplit('/').next().unwrap().parse().unwrap();
            let prim = &mesh_json["primitives"][prim_index];
            let attr = |k: &str| {
                prim["attributes"][k]
                    .as_u64()
                    .map(|a| raw.accessor(a as usize))
            };
            let mut positions: Vec<Vec3> = attr("POSITION")
                .unwrap()
                .iter()
                .map(|r| Vec3::from_slice(r))
                .collect();
            // morph targets
            if let Some(w) = &r.weights[node] {
                assert_eq!(p.morph_weights.len(), w.len(), "{what}");
                for (a, b) in p.morph_weights.iter().zip(w) {
                    assert!(
                        (a - b).abs() < 1e-5,
                        "{what}: weights {:?} vs {w:?}",
                        p.morph_weights
                    );
                }
                for (k, target) in prim["targets"].as_array().unwrap().iter().enumerate() {
                    let d = raw.accessor(target["POSITION"].as_u64().unwrap() as usize);
                    for (p, d) in positions.iter_mut().zip(d) {
                        *p += w[k] * Vec3::from_slice(&d);
                    }
                }
            }
            // skinning, or the node's transform
            let world: Vec<Vec3> = match node_json["skin"].as_u64() {
                Some(s) => {
                    let skin = &raw.json["skins"][s as usize];
                    let joints: Vec<usize> = skin["joints"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|j| j.as_u64().unwrap() as usize)
                        .collect();
                    let ibm: Vec<Mat4> = raw
                        .accessor(skin["inverseBindMatrices"].as_u64().unwrap() as usize)
                        .iter()
                        .map(|m| Mat4::from_cols_slice(m))
                        .collect();
                    assert_eq!(p.joint_matrices.len(), joints.len(), "{what}");
                    for (j, &jn) in joints.iter().enumerate() {
                        let want = r.globals[node].inverse() * r.globals[jn] * ibm[j];
                        near_mat(p.joint_matrices[j], want, &format!("{what}: joint {j}"));
                    }
                    let vj = attr("JOINTS_0").unwrap();
                    let vw = attr("WEIGHTS_0").unwrap();
                    positions
                        .iter()
                        .enumerate()
                        .map(|(v, pos)| {
                            let sum: f32 = vw[v].iter().sum();
                            let mut m = Mat4::ZERO;
                            for k in 0..4 {
                                let j = vj[v][k] as usize;
                                if vw[v][k] > 0.0 {
                                    m += r.globals[joints[j]] * ibm[j] * (vw[v][k] / sum);
                                }
                            }
                            m.transform_point3(*pos)
                        })
                        .collect()
                }
                None => positions
                    .iter()
                    .map(|q| r.globals[node].transform_point3(*q))
                    .collect(),
            };
            // the loader unshares the vertices of meshes without normals
            let indices: Vec<usize> = prim["indices"]
                .as_u64()
                .map(|a| {
                    raw.accessor(a as usize)
                        .iter()
                        .map(|r| r[0] as usize)
                        .collect()
                })
                .unwrap_or_else(|| (0..world.len()).collect());
            let expected: Vec<Vec3> = if scene.meshes[inst.mesh].flat {
                indices.iter().map(|&i| world[i]).collect()
            } else {
                world
            };
            let posed = pose.skinned_mesh(&scene, ii);
            assert_eq!(posed.positions.len(), expected.len(), "{what}");
            for (v, (a, b)) in posed.positions.iter().zip(&expected).enumerate() {
                near_vec(*a, *b, &format!("{what}: vertex {v}"));
            }
        }
    }
    scene
}

#[test]
fn animated_triangle_turns_through_its_keys() {
    let scene = check_model("AnimatedTriangle");
    // key 1 at 0.25 s of the 1 s period is 90° about z: X goes to Y
    let pose = scene.pose(0.25, &Playback::default());
    near_vec(pose.nodes[0].transform_vector3(Vec3::X), Vec3::Y, "t 0.25");
    // looping: 1.25 s is 0.25 s again, and 0.125 s is halfway (45°)
    let looping = Playback {
        looping: true,
        ..Playback::default()
    };
    near_vec(
        scene.pose(1.25, &looping).nodes[0].transform_vector3(Vec3::X),
        Vec3::Y,
        "t 1.25 looped",
    );
    let half = Vec3::new(1.0, 1.0, 0.0).normalize();
    near_vec(
        scene.pose(0.125, &looping).nodes[0].transform_vector3(Vec3::X),
        half,
        "t 0.125",
    );
}

#[test]
fn box_animated_moves_its_child() {
    let scene = check_model("BoxAnimated");
    // node 2 (a mesh, child of node 1, child of the translated node 0) turns
    // from 1.25 s to 2.5 s and rides node 0's translation
    let at = |t: f64| scene.pose(t, &Playback::default());
    let inst = scene
        .instances
        .iter()
        .position(|i| i.node == Some(2))
        .expect("node 2's mesh");
    let (a, b) = (
        at(1.25).instances[inst].world,
        at(2.5).instances[inst].world,
    );
    assert!(!a.abs_diff_eq(b, 1e-3), "the child moves between its keys");
    // before its first key (1.25 s) node 2 holds its first rotation while node
    // 0's translation carries it
    let (a, b) = (at(0.0).nodes[2], at(1.0).nodes[2]);
    assert!(glam::Mat3::from_mat4(a).abs_diff_eq(glam::Mat3::from_mat4(b), 1e-6));
    assert!((a.w_axis - b.w_axis).length() > 1e-3, "node 0 carries it");
}

#[test]
fn simple_skin_bends_at_its_keys() {
    let scene = check_model("SimpleSkin");
    assert_eq!(scene.skins.len(), 1);
    assert_eq!(scene.skins[0].joints, vec![1, 2]);
    assert_eq!(scene.instances[0].skin, Some(0));
    // the mesh has no normals: flat, and its skin attributes follow the
    // unshared vertices
    let mesh = &scene.meshes[scene.instances[0].mesh];
    assert!(mesh.flat && mesh.joints.len() == mesh.positions.len());
    // the bend moves vertices: the rest pose differs from a later key
    let p0 = scene
        .pose(0.0, &Playback::default())
        .skinned_mesh(&scene, 0);
    let p1 = scene
        .pose(1.5, &Playback::default())
        .skinned_mesh(&scene, 0);
    assert!(p0
        .positions
        .iter()
        .zip(&p1.positions)
        .any(|(a, b)| (*a - *b).length() > 0.1));
}

#[test]
fn rigged_simple_holds_its_first_key_before_it() {
    let scene = check_model("RiggedSimple");
    let first = scene.animations[0].channels[0].sampler.times[0] as f64;
    assert!(first > 0.04, "the first key is at {first} s");
    let (a, b) = (
        scene.pose(0.0, &Playback::default()),
        scene.pose(first, &Playback::default()),
    );
    assert_eq!(a.nodes, b.nodes);
    assert_eq!(a.instances, b.instances);
}

#[test]
fn simple_morph_weights_are_the_keys_at_key_times() {
    let scene = check_model("SimpleMorph");
    assert_eq!(
        scene.instances[0].morph_weights,
        vec![0.5, 0.5],
        "the mesh's default weights"
    );
    let raw = RawGltf::read(&animated_corpus("SimpleMorph"));
    let ch = &raw_channels(&raw)[0];
    for (k, &t) in ch.times.iter().enumerate() {
        let pose = scene.pose(t as f64, &Playback::default());
        assert_eq!(
            pose.instances[0].morph_weights,
            ch.values[2 * k..2 * k + 2].to_vec(),
            "t {t}"
        );
    }
}
