//! Posing a scene at a time: the selected animations sampled, the node hierarchy
//! multiplied out (glTF 2.0 §3.5.3), skin joint matrices (§3.7.3) and morph
//! weights per instance, and the lights and cameras carried by their nodes.

use super::{ChannelPath, Playback};
use crate::scene::camera::NamedCamera;
use crate::scene::light::Light;
use crate::scene::model::{Aabb, Instance, Scene};
use crate::scene::node::world_transforms;
use glam::{Mat4, Quat, Vec3};

/// One instance at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct InstancePose {
    /// Object-to-world matrix: the world matrix of the instance's node, or
    /// [`Instance::transform`] for an instance without a node.
    pub world: Mat4,
    /// Skin joint matrices, one per joint of the instance's skin (empty when the
    /// instance is not skinned): `inverse(world) · global(joint) · inverseBind`, so
    /// a skinned vertex is `world · Σ wᵢ · joint_matrices[jᵢ] · p`, which is
    /// `Σ wᵢ · global(jointᵢ) · inverseBindᵢ · p`: the node transform of the
    /// skinned mesh cancels out, as glTF 2.0 §3.7.3.2 ("Joint Hierarchy")
    /// requires ("Only the joint transforms are applied to the skinned mesh; the
    /// transform of the skinned mesh node MUST be ignored"). Where `world` cannot
    /// be inverted, `world` is the identity and the joint matrices are
    /// `global(joint) · inverseBind`, the same product.
    pub joint_matrices: Vec<Mat4>,
    /// Morph weights, one per morph target of the mesh.
    pub morph_weights: Vec<f32>,
}

/// The scene at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// The animation clock that was sampled, seconds (after looping).
    pub time: f64,
    /// World matrix of every node ([`Scene::nodes`]).
    pub nodes: Vec<Mat4>,
    /// One per [`Scene::instances`].
    pub instances: Vec<InstancePose>,
    /// [`Scene::lights`], those on nodes placed by their node.
    pub lights: Vec<Light>,
    /// [`Scene::cameras`], those on nodes placed by their node.
    pub cameras: Vec<NamedCamera>,
}

/// A node's local transform while posing: rest TRS, overwritten by channels.
#[derive(Debug, Clone, Copy)]
struct Trs {
    translation: Vec3,
    rotation: Quat,
    scale: Vec3,
}

impl Scene {
    /// The scene at `time_seconds` on the clock of `playback`'s animations
    /// (wrapped when it loops). Nodes no channel drives keep their rest
    /// transform, so a still scene, [`crate::scene::Selection::None`], or a scene
    /// without animations gives the rest pose: instance world matrices equal to
    /// [`Instance::transform`] and lights and cameras as loaded.
    pub fn pose(&self, time_seconds: f64, playback: &Playback) -> Pose {
        let time = playback.local_time(self, time_seconds);
        let mut trs: Vec<Option<Trs>> = vec![None; self.nodes.len()];
        let mut weights: Vec<Option<Vec<f32>>> = vec![None; self.nodes.len()];
        for anim in playback.animations(self) {
            for ch in &anim.channels {
                let Some(node) = self.nodes.get(ch.node) else {
                    continue;
                };
                if ch.path == ChannelPath::Weights {
                    let w = weights[ch.node].get_or_insert_with(|| node.weights.clone());
                    ch.sampler.sample_into(time, w);
                    continue;
                }
                let t = trs[ch.node].get_or_insert_with(|| {
                    let (translation, rotation, scale) = node.rest.trs();
                    Trs {
                        translation,
                        rotation,
                        scale,
                    }
                });
                match ch.path {
                    ChannelPath::Translation => {
                        let mut v = t.translation.to_array();
                        ch.sampler.sample_into(time, &mut v);
                        t.translation = Vec3::from_array(v);
                    }
                    ChannelPath::Scale => {
                        let mut v = t.scale.to_array();
                        ch.sampler.sample_into(time, &mut v);
                        t.scale = Vec3::from_array(v);
                    }
                    ChannelPath::Rotation => {
                        if let Some(q) = ch.sampler.sample_rotation(time) {
                            t.rotation = q;
                        }
                    }
                    ChannelPath::Weights => {}
                }
            }
        }
        let nodes = world_transforms(&self.nodes, |i| match trs[i] {
            // T · R · S (glTF 2.0 §3.5.3)
            Some(t) => Mat4::from_scale_rotation_translation(t.scale, t.rotation, t.translation),
            None => self.nodes[i].rest.matrix(),
        });
        let instances = self
            .instances
            .iter()
            .map(|inst| self.pose_instance(inst, &nodes, &weights))
            .collect();
        let lights = placed(&self.lights, &nodes, |l| l.node, Light::place);
        let cameras = placed(&self.cameras, &nodes, |c| c.node, |c, w| c.camera.place(w));
        Pose {
            time,
            nodes,
            instances,
            lights,
            cameras,
        }
    }

    /// The rest pose (no animation).
    pub fn rest_pose(&self) -> Pose {
        self.pose(0.0, &Playback::none())
    }

    fn pose_instance(
        &self,
        inst: &Instance,
        nodes: &[Mat4],
        weights: &[Option<Vec<f32>>],
    ) -> InstancePose {
        let mut world = inst
            .node
            .and_then(|n| nodes.get(n))
            .copied()
            .unwrap_or(inst.transform);
        let morph_weights = inst
            .node
            .and_then(|n| weights.get(n))
            .and_then(Option::as_ref)
            .filter(|w| w.len() == inst.morph_weights.len())
            .cloned()
            .unwrap_or_else(|| inst.morph_weights.clone());
        let mut joint_matrices = Vec::new();
        if let Some(skin) = inst.skin.and_then(|s| self.skins.get(s)) {
            // jointMatrix(j) = inverse(global(mesh node)) · global(joint j) ·
            // inverseBindMatrix(j) (glTF 2.0 §3.7.3; the glTF tutorial on skins).
            let inverse = world.inverse();
            let invertible = world.determinant().abs() > f32::MIN_POSITIVE && inverse.is_finite();
            if !invertible {
                world = Mat4::IDENTITY;
            }
            joint_matrices = skin
                .joints
                .iter()
                .zip(&skin.inverse_bind_matrices)
                .map(|(&j, ibm)| {
                    let global = nodes.get(j).copied().unwrap_or_default() * *ibm;
                    if invertible {
                        inverse * global
                    } else {
                        global
                    }
                })
                .collect();
        }
        InstancePose {
            world,
            joint_matrices,
            morph_weights,
        }
    }
}

impl Pose {
    /// World bounds of the posed instances: rigid, unmorphed instances by their
    /// mesh bounds, skinned or morphed ones by their deformed vertices
    /// ([`Pose::skinned_mesh`]).
    pub fn bounds(&self, scene: &Scene) -> Aabb {
        let mut b = Aabb::EMPTY;
        for (i, (inst, p)) in scene.instances.iter().zip(&self.instances).enumerate() {
            let Some(mesh) = scene.meshes.get(inst.mesh) else {
                continue;
            };
            let deformed =
                !p.joint_matrices.is_empty() || p.morph_weights.iter().any(|&w| w != 0.0);
            if deformed {
                for q in self.skinned_mesh(scene, i).positions {
                    b.add(q);
                }
            } else {
                let t = mesh.bounds().transformed(&p.world);
                if !t.is_empty() {
                    b.add(t.min);
                    b.add(t.max);
                }
            }
        }
        b
    }
}

/// Copies of `items` (lights, cameras), those on a node (`node`) placed by its
/// world matrix among `nodes`.
fn placed<T: Clone>(
    items: &[T],
    nodes: &[Mat4],
    node: impl Fn(&T) -> Option<usize>,
    place: impl Fn(&mut T, &Mat4),
) -> Vec<T> {
    items
        .iter()
        .map(|item| {
            let mut item = item.clone();
            if let Some(w) = node(&item).and_then(|n| nodes.get(n)) {
                place(&mut item, w);
            }
            item
        })
        .collect()
}
