//! A hand-built skinned and morphed triangle (8 joints on a small hierarchy,
//! 4 or 8 influences per vertex, normals, tangents, one morph target displacing
//! all three, node 1's translation and node 2's rotation animated over 0..1 s),
//! with the constants it is made of: the scene of tests/scene_skinning.rs (CPU
//! oracle) and tests/gpu_skinning.rs (GPU against CPU).

use super::anim_gltf::{node_scene, write, ChannelSpec, GltfBuilder};
use fxgraph::scene::Scene;
use glam::{Mat4, Quat, Vec3, Vec4};
use serde_json::json;

/// Joints: node 1 (a root) and its children, nodes 2..=8.
pub const JOINTS: usize = 8;

/// Rest TRS of joint node `n` (1..=8).
pub fn joint_rest(n: usize) -> (Vec3, Quat, Vec3) {
    if n == 1 {
        return (
            Vec3::new(0.0, 1.0, 0.0),
            Quat::from_rotation_x(0.2),
            Vec3::ONE,
        );
    }
    let k = n as f32;
    (
        Vec3::new(0.3 * k, 0.0, 0.1 * k),
        Quat::from_rotation_z(0.1 * k),
        Vec3::new(1.0 + 0.1 * k, 1.0, 1.0 - 0.05 * k),
    )
}

/// Animated: node 1's translation and node 2's rotation, LINEAR over 0..1 s.
pub const T1: [Vec3; 2] = [Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.5, 2.0, -1.0)];
pub fn r2() -> [Quat; 2] {
    [joint_rest(2).1, Quat::from_rotation_y(1.2)]
}

/// The bind pose's inverse global matrices, perturbed so that they are not
/// simply inverses (any matrix must work).
pub fn inverse_bind(j: usize) -> Mat4 {
    (global_at(j + 1, None) * Mat4::from_rotation_y(0.1 * j as f32)).inverse()
}

/// Global matrix of joint node `n` with node 1's translation and node 2's
/// rotation replaced (`None`: the rest pose).
pub fn global_at(n: usize, anim: Option<(Vec3, Quat)>) -> Mat4 {
    let local = |n: usize| {
        let (mut t, mut r, s) = joint_rest(n);
        if let Some((t1, r2)) = anim {
            if n == 1 {
                t = t1;
            }
            if n == 2 {
                r = r2;
            }
        }
        Mat4::from_translation(t) * Mat4::from_quat(r) * Mat4::from_scale(s)
    };
    if n == 1 {
        local(1)
    } else {
        local(1) * local(n)
    }
}

/// Per vertex: 8 joints and weights (the last 4 in `JOINTS_1`/`WEIGHTS_1`).
pub const SKIN: [([u16; 8], [f32; 8]); 3] = [
    (
        [0, 1, 0, 0, 0, 0, 0, 0],
        [0.7, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ),
    (
        [3, 0, 0, 0, 0, 0, 0, 0],
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ),
    (
        [0, 1, 2, 3, 4, 5, 6, 7],
        [0.05, 0.1, 0.15, 0.2, 0.05, 0.1, 0.15, 0.2],
    ),
];
pub const NORMALS: [Vec3; 3] = [Vec3::Z, Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.8, 0.0, 0.6)];
pub const TANGENTS: [Vec4; 3] = [
    Vec4::new(1.0, 0.0, 0.0, 1.0),
    Vec4::new(1.0, 0.0, 0.0, -1.0),
    Vec4::new(0.0, 1.0, 0.0, 1.0),
];
/// One morph target (rest weight 0.5) displacing positions, normals, tangents.
pub const MORPH: [Vec3; 3] = [
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(0.5, 0.0, 0.0),
    Vec3::new(0.0, -0.25, 0.5),
];
pub const MORPH_N: Vec3 = Vec3::new(0.1, 0.0, 0.0);
pub const MORPH_T: Vec3 = Vec3::new(0.0, 0.2, 0.0);
pub const MORPH_WEIGHT: f32 = 0.5;

/// The skinned, morphed triangle on node 0 (translated and turned: both must be
/// ignored), joints on nodes 1..=8.
pub fn skinned_scene(eight: bool) -> Scene {
    let mut b = GltfBuilder::default();
    let joints0: Vec<u16> = SKIN.iter().flat_map(|(j, _)| j[..4].to_vec()).collect();
    let weights0: Vec<f32> = SKIN.iter().flat_map(|(_, w)| w[..4].to_vec()).collect();
    let joints1: Vec<u16> = SKIN.iter().flat_map(|(j, _)| j[4..].to_vec()).collect();
    let weights1: Vec<f32> = SKIN.iter().flat_map(|(_, w)| w[4..].to_vec()).collect();
    let normals: Vec<f32> = NORMALS.iter().flat_map(|n| n.to_array()).collect();
    let tangents: Vec<f32> = TANGENTS.iter().flat_map(|t| t.to_array()).collect();
    let mut attributes = json!({
        "JOINTS_0": b.u16s(&joints0, "VEC4", false),
        "WEIGHTS_0": b.f32s(&weights0, "VEC4"),
        "NORMAL": b.f32s(&normals, "VEC3"),
        "TANGENT": b.f32s(&tangents, "VEC4"),
    });
    if eight {
        attributes["JOINTS_1"] = json!(b.u16s(&joints1, "VEC4", false));
        attributes["WEIGHTS_1"] = json!(b.f32s(&weights1, "VEC4"));
    }
    let target = json!([{
        "POSITION": b.f32s(&MORPH.iter().flat_map(|d| d.to_array()).collect::<Vec<_>>(), "VEC3"),
        "NORMAL": b.f32s(&MORPH_N.to_array().repeat(3), "VEC3"),
        "TANGENT": b.f32s(&MORPH_T.to_array().repeat(3), "VEC3"),
    }]);
    let joint_nodes: Vec<serde_json::Value> = (1..=JOINTS)
        .map(|n| {
            let (t, r, s) = joint_rest(n);
            let mut node = json!({
                "name": format!("joint{}", n - 1),
                "translation": t.to_array(), "rotation": r.to_array(), "scale": s.to_array()
            });
            if n == 1 {
                node["children"] = json!((2..=JOINTS).collect::<Vec<_>>());
            }
            node
        })
        .collect();
    let t1: Vec<f32> = T1.iter().flat_map(|t| t.to_array()).collect();
    let r2: Vec<f32> = r2().iter().flat_map(|q| q.to_array()).collect();
    let mut doc = node_scene(
        &mut b,
        attributes,
        Some(target),
        joint_nodes,
        &[1],
        &[vec![
            ChannelSpec {
                node: 1,
                path: "translation",
                interpolation: "LINEAR",
                times: &[0.0, 1.0],
                values: &t1,
            },
            ChannelSpec {
                node: 2,
                path: "rotation",
                interpolation: "LINEAR",
                times: &[0.0, 1.0],
                values: &r2,
            },
        ]],
    );
    let ibm: Vec<f32> = (0..JOINTS)
        .flat_map(|j| inverse_bind(j).to_cols_array())
        .collect();
    doc["skins"] = json!([{
        "joints": (1..=JOINTS).collect::<Vec<_>>(),
        "inverseBindMatrices": b.f32s(&ibm, "MAT4"),
    }]);
    doc["nodes"][0]["skin"] = json!(0);
    doc["nodes"][0]["translation"] = json!([5.0, 0.0, 0.0]);
    doc["nodes"][0]["rotation"] = json!(Quat::from_rotation_y(0.3).to_array());
    doc["meshes"][0]["weights"] = json!([MORPH_WEIGHT]);
    let (_dir, path) = write(&b.finish(doc), "skinned.gltf");
    Scene::load(path.to_str().unwrap()).unwrap()
}
