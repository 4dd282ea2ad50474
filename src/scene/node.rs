//! The node hierarchy of a scene (glTF 2.0 §3.5.2 "Nodes and Hierarchy", §3.5.3
//! "Transformations"): every node's name, parent, children and rest local
//! transform. Instances, lights and cameras that come from a node name it, so that
//! animating the node moves them ([`crate::scene::animation`]).
//!
//! Built-in and hand-made scenes have no nodes: their instances, lights and cameras
//! are placed by their own transforms and never move.

use glam::{Mat4, Quat, Vec3};

/// Deepest node hierarchy accepted.
pub const MAX_NODE_DEPTH: usize = 64;

/// A node's local transform as the source gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodeTransform {
    /// Translation, rotation (unit quaternion) and scale, composed `T · R · S`
    /// (glTF 2.0 §3.5.3: "first the scale is applied to the vertices, then the
    /// rotation, and then the translation").
    Trs {
        translation: Vec3,
        rotation: Quat,
        scale: Vec3,
    },
    /// A local matrix (glTF `matrix`; such a node may not be animated).
    Matrix(Mat4),
}

impl Default for NodeTransform {
    fn default() -> Self {
        NodeTransform::Trs {
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        }
    }
}

impl NodeTransform {
    /// The local matrix: `T · R · S`, or the matrix as given.
    pub fn matrix(&self) -> Mat4 {
        match *self {
            NodeTransform::Trs {
                translation,
                rotation,
                scale,
            } => Mat4::from_scale_rotation_translation(scale, rotation, translation),
            NodeTransform::Matrix(m) => m,
        }
    }

    /// Translation, rotation and scale (a matrix is decomposed, losing any shear,
    /// which glTF forbids anyway).
    pub fn trs(&self) -> (Vec3, Quat, Vec3) {
        match *self {
            NodeTransform::Trs {
                translation,
                rotation,
                scale,
            } => (translation, rotation, scale),
            NodeTransform::Matrix(m) => {
                let (scale, rotation, translation) = m.to_scale_rotation_translation();
                (translation, rotation, scale)
            }
        }
    }
}

/// One node of the hierarchy.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Node {
    /// The source's name, or `node N`.
    pub name: String,
    /// The parent node (`None` for a root).
    pub parent: Option<usize>,
    /// Child nodes, in the source's order.
    pub children: Vec<usize>,
    /// The rest (not animated) local transform.
    pub rest: NodeTransform,
    /// Rest morph-target weights of the node's mesh (glTF `node.weights`, else
    /// `mesh.weights`, else zeros; empty when the node has no morphed mesh).
    pub weights: Vec<f32>,
}

/// World (global) transforms of every node: each is its parent's world matrix
/// times its own local matrix (glTF 2.0 §3.5.3), `local(i)` giving node `i`'s local
/// matrix. Nodes whose parent chain does not end at a root within `nodes.len()`
/// steps (a cycle, or a parent index out of range; [`crate::scene::Scene::validate`]
/// rejects both) get their local matrix alone.
pub fn world_transforms(nodes: &[Node], local: impl Fn(usize) -> Mat4) -> Vec<Mat4> {
    let n = nodes.len();
    let mut world: Vec<Option<Mat4>> = vec![None; n];
    let mut chain = Vec::new();
    for start in 0..n {
        // Walk up to the first node whose world matrix is known (or a root), then
        // come back down multiplying.
        chain.clear();
        let mut i = start;
        let mut base = Mat4::IDENTITY;
        let mut cyclic = false;
        loop {
            if let Some(w) = world[i] {
                base = w;
                break;
            }
            chain.push(i);
            match nodes[i].parent {
                Some(_) if chain.len() > n => {
                    cyclic = true;
                    break;
                }
                Some(p) if p < n => i = p,
                _ => break,
            }
        }
        if cyclic {
            world[start] = Some(local(start));
            continue;
        }
        for &j in chain.iter().rev() {
            base *= local(j);
            world[j] = Some(base);
        }
    }
    world.into_iter().map(|w| w.unwrap_or_default()).collect()
}

/// Checks that parent and child links agree, are in range, and form strict trees
/// no deeper than `max_depth`.
pub fn check_hierarchy(nodes: &[Node], max_depth: usize) -> Result<(), String> {
    for (i, node) in nodes.iter().enumerate() {
        if let Some(p) = node.parent {
            let parent = nodes
                .get(p)
                .ok_or_else(|| format!("node {i}: parent {p} is out of range"))?;
            if !parent.children.contains(&i) {
                return Err(format!("node {i}: parent {p} does not list it as a child"));
            }
        }
        for &c in &node.children {
            let child = nodes
                .get(c)
                .ok_or_else(|| format!("node {i}: child {c} is out of range"))?;
            if child.parent != Some(i) {
                return Err(format!(
                    "node {c} is a child of node {i} but its parent is {:?} (each node \
                     has at most one parent, glTF 2.0 §3.5.2)",
                    child.parent
                ));
            }
        }
        let mut depth = 0;
        let mut at = i;
        while let Some(p) = nodes[at].parent {
            depth += 1;
            if depth > max_depth {
                return Err(format!(
                    "node {i}: the hierarchy is deeper than {max_depth} levels or has a cycle"
                ));
            }
            at = p;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain() -> Vec<Node> {
        let t = |x: f32| NodeTransform::Trs {
            translation: Vec3::new(x, 0.0, 0.0),
            rotation: Quat::IDENTITY,
            scale: Vec3::ONE,
        };
        // 2 -> 0 -> 1 (node 2 is the root; listed last to test the order)
        vec![
            Node {
                name: "a".into(),
                parent: Some(2),
                children: vec![1],
                rest: t(1.0),
                ..Default::default()
            },
            Node {
                name: "b".into(),
                parent: Some(0),
                rest: t(10.0),
                ..Default::default()
            },
            Node {
                name: "root".into(),
                children: vec![0],
                rest: t(100.0),
                ..Default::default()
            },
        ]
    }

    #[test]
    fn world_is_parent_times_local() {
        let nodes = chain();
        check_hierarchy(&nodes, 64).unwrap();
        let w = world_transforms(&nodes, |i| nodes[i].rest.matrix());
        assert_eq!(w[2].w_axis.x, 100.0);
        assert_eq!(w[0].w_axis.x, 101.0);
        assert_eq!(w[1].w_axis.x, 111.0);
    }

    #[test]
    fn cycles_and_bad_links_are_reported() {
        let mut nodes = chain();
        nodes[2].parent = Some(1);
        nodes[1].children.push(2);
        let e = check_hierarchy(&nodes, 64).unwrap_err();
        assert!(e.contains("cycle"), "{e}");
        // and world_transforms still ends
        let w = world_transforms(&nodes, |i| nodes[i].rest.matrix());
        assert_eq!(w.len(), 3);
        let mut nodes = chain();
        nodes[1].parent = Some(2);
        assert!(check_hierarchy(&nodes, 64).is_err());
    }

    #[test]
    fn matrix_and_trs_agree() {
        let trs = NodeTransform::Trs {
            translation: Vec3::new(1.0, 2.0, 3.0),
            rotation: Quat::from_rotation_y(0.7),
            scale: Vec3::new(2.0, 2.0, 2.0),
        };
        let m = NodeTransform::Matrix(trs.matrix());
        let (t, r, s) = m.trs();
        assert!((t - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-5);
        assert!(r.dot(Quat::from_rotation_y(0.7)).abs() > 0.99999);
        assert!((s - Vec3::splat(2.0)).length() < 1e-5);
    }
}
