//! The glTF node hierarchy kept in the scene ([`Node`]): every node of the file
//! (by glTF index), its parent, children, rest transform and rest morph weights.
//! glTF 2.0 §3.5.2 requires disjoint strict trees: a node listed as the child of
//! two nodes (or twice), or a cycle, is an error.

use crate::scene::node::{check_hierarchy, Node, NodeTransform, MAX_NODE_DEPTH};
use glam::{Mat4, Quat, Vec3};

/// A node's rest local transform.
pub(super) fn rest_transform(node: &gltf::Node) -> NodeTransform {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            NodeTransform::Matrix(Mat4::from_cols_array_2d(&matrix))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => NodeTransform::Trs {
            translation: Vec3::from(translation),
            rotation: Quat::from_array(rotation),
            scale: Vec3::from(scale),
        },
    }
}

/// The rest morph weights of a node's mesh: `node.weights`, else
/// `mesh.weights`, else zeros, one per morph target (glTF 2.0 §3.7.2.2); empty
/// for a node without a mesh or a mesh without morph targets. All primitives of
/// the mesh must have the same number of targets.
pub(super) fn rest_weights(file: &str, node: &gltf::Node) -> Result<Vec<f32>, String> {
    let Some(mesh) = node.mesh() else {
        return Ok(Vec::new());
    };
    let mut counts = mesh.primitives().map(|p| p.morph_targets().len());
    let targets = counts.next().unwrap_or(0);
    if let Some(other) = counts.find(|&c| c != targets) {
        return Err(format!(
            "mesh {}: its primitives have {targets} and {other} morph targets (glTF requires \
             the same number)",
            mesh.index()
        ));
    }
    let given = node.weights().or_else(|| mesh.weights());
    let mut weights = vec![0.0; targets];
    if let Some(w) = given {
        if w.len() != targets {
            log::warn!(
                "{file}: node {}: {} morph weights for {targets} morph targets (missing ones \
                 are 0)",
                node.index(),
                w.len()
            );
        }
        for (d, &s) in weights.iter_mut().zip(w) {
            *d = s;
        }
    }
    if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
        return Err(format!(
            "node {}: morph weight {i} is {} (not finite)",
            node.index(),
            weights[i]
        ));
    }
    Ok(weights)
}

/// Every node of the document, with parents from the `children` lists; checked
/// to form trees no deeper than [`MAX_NODE_DEPTH`].
pub(super) fn read_nodes(file: &str, doc: &gltf::Document) -> Result<Vec<Node>, String> {
    let mut nodes = Vec::with_capacity(doc.nodes().len());
    for node in doc.nodes() {
        nodes.push(Node {
            name: node
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("node {}", node.index())),
            parent: None,
            children: node.children().map(|c| c.index()).collect(),
            rest: rest_transform(&node),
            weights: rest_weights(file, &node)?,
        });
    }
    for i in 0..nodes.len() {
        for c in nodes[i].children.clone() {
            let child = nodes
                .get_mut(c)
                .ok_or_else(|| format!("node {i}: child {c} is out of range"))?;
            if let Some(p) = child.parent {
                return Err(format!(
                    "node {c} is a child of node {p} and of node {i} (glTF 2.0 §3.5.2: each \
                     node has at most one parent)"
                ));
            }
            child.parent = Some(i);
        }
    }
    check_hierarchy(&nodes, MAX_NODE_DEPTH)?;
    Ok(nodes)
}
