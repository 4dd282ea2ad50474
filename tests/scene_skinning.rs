//! Skins and morph targets on the CPU (no GPU): a hand-built skinned and morphed
//! triangle posed through the loader, compared with skinning written in this file
//! from glTF 2.0 §3.7.3 ("Skins": vertex matrix Σ wₖ · global(jointₖ) ·
//! inverseBindₖ, the skinned mesh node's own transform ignored) and §3.7.2.2
//! ("Morph Targets": displacements added before skinning), with 8 influences,
//! normals by the inverse transpose and tangents by the matrix.
//!
//! Tolerances: 1e-4 on positions (coordinates up to ~10), 1e-5 on unit vectors
//! and joint matrices.

use crate::common;

use common::anim_gltf::{node_scene, write, GltfBuilder, TRIANGLE};
use common::skinned_scene::*;
use fxgraph::scene::{Playback, Scene};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use serde_json::json;

/// The oracle at animation time `s` (0..1): morph, then Σ wₖ global(jₖ) IBMₖ,
/// with 4 influences (renormalised to sum 1, as the loader may) or 8.
fn oracle(s: f32, eight: bool) -> Vec<(Vec3, Vec3, Vec4)> {
    let anim = (T1[0].lerp(T1[1], s), r2()[0].slerp(r2()[1], s));
    (0..3)
        .map(|v| {
            let (joints, weights) = SKIN[v];
            let n = if eight { 8 } else { 4 };
            let sum: f32 = weights[..n].iter().sum();
            let mut m = Mat4::ZERO;
            for k in 0..n {
                let j = joints[k] as usize;
                m += global_at(j + 1, Some(anim)) * inverse_bind(j) * (weights[k] / sum);
            }
            let p = TRIANGLE[v] + MORPH_WEIGHT * MORPH[v];
            let n0 = NORMALS[v] + MORPH_WEIGHT * MORPH_N;
            let t0 = TANGENTS[v].truncate() + MORPH_WEIGHT * MORPH_T;
            let m3 = Mat3::from_mat4(m);
            (
                m.transform_point3(p),
                (m3.inverse().transpose() * n0).normalize(),
                (m3 * t0).normalize().extend(TANGENTS[v].w),
            )
        })
        .collect()
}

#[test]
fn skinned_and_morphed_vertices_match_the_spec() {
    for eight in [false, true] {
        let scene = skinned_scene(eight);
        assert_eq!(scene.instances[0].skin, Some(0));
        assert_eq!(scene.meshes[0].joints1.is_empty(), !eight);
        for s in [0.0f32, 0.25, 0.5, 1.0] {
            let pose = scene.pose(s as f64, &Playback::default());
            let posed = pose.skinned_mesh(&scene, 0);
            let tangents = posed.tangents.as_ref().expect("tangents");
            for (v, (p, n, t)) in oracle(s, eight).into_iter().enumerate() {
                let what = format!(
                    "{} influences, t {s}, vertex {v}",
                    if eight { 8 } else { 4 }
                );
                assert!(
                    (posed.positions[v] - p).length() < 1e-4,
                    "{what}: {} vs {p}",
                    posed.positions[v]
                );
                assert!(
                    (posed.normals[v] - n).length() < 1e-5,
                    "{what}: normal {} vs {n}",
                    posed.normals[v]
                );
                assert!(
                    (tangents[v] - t).length() < 1e-5,
                    "{what}: tangent {} vs {t}",
                    tangents[v]
                );
            }
        }
    }
}

#[test]
fn joint_matrices_cancel_the_mesh_node() {
    let scene = skinned_scene(true);
    let pose = scene.pose(0.5, &Playback::default());
    let inst = &pose.instances[0];
    let mesh_global = Mat4::from_translation(Vec3::new(5.0, 0.0, 0.0))
        * Mat4::from_quat(Quat::from_rotation_y(0.3));
    assert!(inst.world.abs_diff_eq(mesh_global, 1e-6), "{}", inst.world);
    let anim = (T1[0].lerp(T1[1], 0.5), r2()[0].slerp(r2()[1], 0.5));
    assert_eq!(inst.joint_matrices.len(), JOINTS);
    for j in 0..JOINTS {
        // jointMatrix = inverse(global(mesh node)) · global(joint) · inverseBind
        let want = mesh_global.inverse() * global_at(j + 1, Some(anim)) * inverse_bind(j);
        assert!(
            inst.joint_matrices[j].abs_diff_eq(want, 1e-5),
            "joint {j}: {} vs {want}",
            inst.joint_matrices[j]
        );
        // and world · jointMatrix is the joint alone (the mesh node cancels)
        let alone = global_at(j + 1, Some(anim)) * inverse_bind(j);
        assert!((inst.world * inst.joint_matrices[j]).abs_diff_eq(alone, 1e-4));
    }
    assert_eq!(inst.morph_weights, vec![MORPH_WEIGHT]);
}

#[test]
fn quantised_weights_are_renormalised() {
    // WEIGHTS_0 as normalised u8 summing to 255 and u8 joints: the same pose as
    // the float weights c / 255 renormalised.
    let mut b = GltfBuilder::default();
    let joints: Vec<u8> = [0u8, 1, 0, 0].repeat(3);
    let weights: Vec<u8> = [[200u8, 55, 0, 0], [0, 255, 0, 0], [128, 127, 0, 0]].concat();
    let attributes = json!({
        "JOINTS_0": b.u8s(&joints, "VEC4", false),
        "WEIGHTS_0": b.u8s(&weights, "VEC4", true),
    });
    let mut doc = node_scene(
        &mut b,
        attributes,
        None,
        vec![
            json!({"translation": [0.0, 2.0, 0.0]}),
            json!({"rotation": Quat::from_rotation_z(1.0).to_array()}),
        ],
        &[1, 2],
        &[],
    );
    doc["skins"] = json!([{"joints": [1, 2]}]);
    doc["nodes"][0]["skin"] = json!(0);
    let (_dir, path) = write(&b.finish(doc), "quantised.gltf");
    let scene = Scene::load(path.to_str().unwrap()).unwrap();
    let posed = scene.rest_pose().skinned_mesh(&scene, 0);
    let joint = [
        Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)),
        Mat4::from_rotation_z(1.0),
    ];
    for v in 0..3 {
        let w = [
            weights[v * 4] as f32 / 255.0,
            weights[v * 4 + 1] as f32 / 255.0,
        ];
        let m = (joint[0] * w[0] + joint[1] * w[1]) * (1.0 / (w[0] + w[1]));
        let want = m.transform_point3(TRIANGLE[v]);
        assert!(
            (posed.positions[v] - want).length() < 1e-5,
            "{} vs {want}",
            posed.positions[v]
        );
    }
}

/// A triangle on node 0 skinned by `joints` and `weights` (4 per vertex, the
/// same for the 3 vertices) with skin 0 = nodes 1 and 2 and the given inverse
/// bind matrices.
fn skinned_triangle(
    joints: [u16; 4],
    weights: [f32; 4],
    ibm: Option<&[Mat4]>,
) -> serde_json::Value {
    let mut b = GltfBuilder::default();
    let attributes = json!({
        "JOINTS_0": b.u16s(&joints.repeat(3), "VEC4", false),
        "WEIGHTS_0": b.f32s(&weights.repeat(3), "VEC4"),
    });
    let ibm = ibm.map(|m| {
        b.f32s(
            &m.iter().flat_map(|m| m.to_cols_array()).collect::<Vec<_>>(),
            "MAT4",
        )
    });
    let mut doc = node_scene(
        &mut b,
        attributes,
        None,
        vec![json!({}), json!({})],
        &[1, 2],
        &[],
    );
    doc["skins"] = json!([{"joints": [1, 2]}]);
    if let Some(ibm) = ibm {
        doc["skins"][0]["inverseBindMatrices"] = json!(ibm);
    }
    doc["nodes"][0]["skin"] = json!(0);
    b.finish(doc)
}

#[test]
fn broken_skins_are_clear_errors() {
    let cases = [
        (
            skinned_triangle([0, 2, 0, 0], [0.5, 0.5, 0.0, 0.0], None),
            "uses joint 2 but skin 0 has 2 joints",
        ),
        (
            skinned_triangle([0, 1, 0, 0], [1.5, -0.5, 0.0, 0.0], None),
            "WEIGHTS_0 of vertex 0 is [1.5, -0.5, 0, 0] (weights must be finite and not negative)",
        ),
        (
            skinned_triangle([0, 1, 0, 0], [0.5, 0.5, 0.0, 0.0], Some(&[Mat4::IDENTITY])),
            "1 inverse bind matrices for 2 joints",
        ),
    ];
    for (doc, expected) in cases {
        let (_dir, path) = write(&doc, "broken_skin.gltf");
        let e = Scene::load(path.to_str().unwrap())
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(e.contains("broken_skin.gltf: "), "{e}");
        assert!(e.contains(expected), "{e}");
    }
}
