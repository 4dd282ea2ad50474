//! The CPU reference of vertex deformation, written straight from glTF 2.0:
//!
//! 1. morph targets (§3.7.2.2 "Morph Targets"): `attribute + Σ weightᵢ ·
//!    targetᵢ.attribute` for POSITION, NORMAL and TANGENT (xyz; w is not
//!    displaced), "applied before any transformation matrices affecting the mesh
//!    vertices such as skinning or node transforms";
//! 2. skinning (§3.7.3.3 "Skinned Mesh Attributes"): the vertex matrix is the
//!    weighted sum `M = Σₖ WEIGHTSₖ · jointMatrix[JOINTSₖ]` over the 4 (or 8, with
//!    `JOINTS_1`/`WEIGHTS_1`) influences; positions `M · p`, normals by the
//!    inverse transpose of `M`'s upper 3×3, tangents by the 3×3 itself (w kept),
//!    both renormalised;
//! 3. the instance's world matrix ([`InstancePose::world`]; for a skinned
//!    instance it cancels the `inverse(world)` inside the joint matrices, so only
//!    the joint transforms apply).
//!
//! A flat-shaded mesh ([`Mesh::flat`]) gets the face normals of the deformed
//! triangles (§3.7.2.2: flat normals are computed for each morph target).
//!
//! This is the oracle the GPU skinning is tested against; it favours clarity over
//! speed.

use super::pose::{InstancePose, Pose};
use crate::scene::model::{Mesh, Scene};
use glam::{Mat3, Mat4, Vec3, Vec4};

/// An instance's vertices in world space at a pose (same order and count as its
/// mesh's).
#[derive(Debug, Clone, PartialEq)]
pub struct PosedMesh {
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Unit tangents (xyz) with the handedness w as stored; `None` when the mesh
    /// has none.
    pub tangents: Option<Vec<Vec4>>,
}

/// The mesh's vertices with its morph targets applied at `weights` (object space;
/// normals not renormalised). Weights beyond the mesh's targets are ignored.
pub fn morph(mesh: &Mesh, weights: &[f32]) -> PosedMesh {
    let mut positions = mesh.positions.clone();
    let mut normals = mesh.normals.clone();
    let mut tangents = mesh.tangents.clone();
    for (target, &w) in mesh.morph_targets.iter().zip(weights) {
        if w == 0.0 {
            continue;
        }
        for (p, d) in positions.iter_mut().zip(&target.positions) {
            *p += w * *d;
        }
        for (n, d) in normals.iter_mut().zip(&target.normals) {
            *n += w * *d;
        }
        if let Some(ts) = tangents.as_mut() {
            for (t, d) in ts.iter_mut().zip(&target.tangents) {
                *t += (w * *d).extend(0.0);
            }
        }
    }
    PosedMesh {
        positions,
        normals,
        tangents,
    }
}

/// The skinning matrix of vertex `v`: `Σₖ weightₖ · joint_matrices[jointₖ]` over
/// `JOINTS_0`/`WEIGHTS_0` and, when present, `JOINTS_1`/`WEIGHTS_1`. `None` when
/// the mesh is not skinned. A joint index beyond `joint_matrices` contributes
/// nothing (the loader rejects such files).
pub fn skin_matrix(mesh: &Mesh, v: usize, joint_matrices: &[Mat4]) -> Option<Mat4> {
    if !mesh.is_skinned() {
        return None;
    }
    let mut m = Mat4::ZERO;
    let sets = [
        (&mesh.joints, &mesh.weights),
        (&mesh.joints1, &mesh.weights1),
    ];
    for (joints, weights) in sets {
        let (Some(j), Some(w)) = (joints.get(v), weights.get(v)) else {
            continue;
        };
        for k in 0..4 {
            if w[k] != 0.0 {
                if let Some(jm) = joint_matrices.get(j[k] as usize) {
                    m += *jm * w[k];
                }
            }
        }
    }
    Some(m)
}

/// Transforms a vertex by `m`: the position as a point, the normal by the inverse
/// transpose of the upper 3×3, the tangent's xyz by the 3×3 (w kept); directions
/// renormalised (kept as they are where the matrix collapses them).
fn transform_vertex(m: &Mat4, p: &mut Vec3, n: &mut Vec3, t: Option<&mut Vec4>) {
    let m3 = Mat3::from_mat4(*m);
    let normal_matrix = m3.inverse().transpose();
    *p = m.transform_point3(*p);
    let nn = if normal_matrix.is_finite() {
        normal_matrix * *n
    } else {
        m3 * *n
    };
    *n = nn.try_normalize().unwrap_or(*n);
    if let Some(t) = t {
        let tt = (m3 * t.truncate()).try_normalize();
        if let Some(tt) = tt {
            *t = tt.extend(t.w);
        }
    }
}

impl Pose {
    /// The world-space vertices of `scene.instances[instance]` at this pose:
    /// morphed, skinned (when the instance has a skin), then placed by the
    /// instance's world matrix. Panics when `instance` is out of range.
    pub fn skinned_mesh(&self, scene: &Scene, instance: usize) -> PosedMesh {
        self.deform(scene, instance, self.instances[instance].world)
    }

    /// The vertices of `scene.instances[instance]` morphed and skinned, in the
    /// instance's object space: what the renderer draws with the instance's world
    /// matrix ([`InstancePose::world`]), which makes them [`Pose::skinned_mesh`].
    pub fn deformed_mesh(&self, scene: &Scene, instance: usize) -> PosedMesh {
        self.deform(scene, instance, Mat4::IDENTITY)
    }

    fn deform(&self, scene: &Scene, instance: usize, world: Mat4) -> PosedMesh {
        let inst = &scene.instances[instance];
        let pose: &InstancePose = &self.instances[instance];
        let mesh = &scene.meshes[inst.mesh];
        let mut out = morph(mesh, &pose.morph_weights);
        let skinned = !pose.joint_matrices.is_empty();
        for v in 0..out.positions.len() {
            let m = match skin_matrix(mesh, v, &pose.joint_matrices).filter(|_| skinned) {
                Some(s) => world * s,
                None => world,
            };
            let t = out.tangents.as_mut().map(|t| &mut t[v]);
            transform_vertex(&m, &mut out.positions[v], &mut out.normals[v], t);
        }
        if mesh.flat {
            for (tri, n) in out
                .positions
                .chunks_exact(3)
                .zip(out.normals.chunks_exact_mut(3))
            {
                let face = (tri[1] - tri[0])
                    .cross(tri[2] - tri[0])
                    .try_normalize()
                    .unwrap_or(Vec3::Y);
                n.fill(face);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::model::MorphTarget;

    #[test]
    fn morph_adds_weighted_displacements() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X],
            normals: vec![Vec3::Z; 2],
            morph_targets: vec![
                MorphTarget {
                    positions: vec![Vec3::Y, Vec3::Y],
                    ..Default::default()
                },
                MorphTarget {
                    positions: vec![Vec3::Z, Vec3::ZERO],
                    normals: vec![Vec3::X, Vec3::X],
                    ..Default::default()
                },
            ],
            ..Default::default()
        };
        let m = morph(&mesh, &[0.5, 2.0]);
        assert_eq!(
            m.positions,
            vec![Vec3::new(0.0, 0.5, 2.0), Vec3::new(1.0, 0.5, 0.0)]
        );
        assert_eq!(m.normals[0], Vec3::new(2.0, 0.0, 1.0));
    }

    #[test]
    fn skin_matrix_blends_joints() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO],
            joints: vec![[1, 0, 0, 0]],
            weights: vec![Vec4::new(0.25, 0.75, 0.0, 0.0)],
            ..Default::default()
        };
        let j = [
            Mat4::from_translation(Vec3::X),
            Mat4::from_translation(Vec3::Y),
        ];
        let m = skin_matrix(&mesh, 0, &j).unwrap();
        assert_eq!(m.transform_point3(Vec3::ZERO), Vec3::new(0.75, 0.25, 0.0));
    }
}
