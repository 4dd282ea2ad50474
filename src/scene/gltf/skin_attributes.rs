//! A primitive's skin attributes (`JOINTS_0/1`, `WEIGHTS_0/1`) and morph targets
//! (`POSITION`, `NORMAL`, `TANGENT` displacements), read and checked; and the
//! skin of an instance.
//!
//! Skin weights are renormalised to sum to 1 over the 8 influences (glTF 2.0
//! §3.7.3.3 asks for sums as close to 1 as possible and notes that quantised
//! weights "should be renormalized"); a vertex whose weights are all 0 gets weight
//! 1 on its first influence (with a warning). Joints of influences of weight 0
//! are set to 0, as the specification recommends, so that any joint index read is
//! in range. `JOINTS_2` and later sets are ignored with a warning.

use super::Converter;
use crate::scene::animation::MAX_MORPH_TARGETS;
use crate::scene::model::{Mesh, MorphTarget};
use glam::{Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::Semantic;

/// One primitive whose skin attributes and morph targets are read: its name in
/// messages (`label`), its glTF mesh (for the default morph weights), the
/// primitive and its attribute reader.
pub(super) struct SkinReader<'p, 'a, 's, F>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    pub(super) conv: &'p Converter<'p>,
    pub(super) label: &'p str,
    pub(super) mesh: &'p gltf::Mesh<'a>,
    pub(super) prim: &'p gltf::Primitive<'a>,
    pub(super) reader: &'p gltf::mesh::Reader<'a, 's, F>,
}

impl<'a, 's, F> SkinReader<'_, 'a, 's, F>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    /// Reads the skin attributes and morph targets into `m` (whose positions,
    /// normals and colours are read already).
    pub(super) fn read(&self, m: &mut Mesh) -> Result<(), String> {
        let (label, prim, reader) = (self.label, self.prim, self.reader);
        let count = m.positions.len();
        for (semantic, acc) in prim.attributes() {
            let (set, types): (u32, &[DataType]) = match semantic {
                Semantic::Joints(n) => (n, &[DataType::U8, DataType::U16]),
                Semantic::Weights(n) => (n, &[DataType::F32, DataType::U8, DataType::U16]),
                _ => continue,
            };
            if set >= 2 {
                log::warn!(
                    "{}: {label}: {semantic:?} ignored (at most 8 joint influences, sets 0 and 1)",
                    self.conv.name
                );
                continue;
            }
            self.conv.check_accessor(
                &format!("{label} {semantic:?}"),
                &acc,
                &[Dimensions::Vec4],
                types,
            )?;
            if acc.count() != count {
                return Err(format!(
                    "{label}: attribute {semantic:?} has {} elements, POSITION has {count}",
                    acc.count()
                ));
            }
        }
        for set in 0..2u32 {
            let joints = reader.read_joints(set);
            let weights = reader.read_weights(set);
            let (joints, weights) = match (joints, weights) {
                (None, None) => break,
                (Some(j), Some(w)) => (j, w),
                _ => {
                    return Err(format!(
                        "{label}: JOINTS_{set} and WEIGHTS_{set} must be given together"
                    ))
                }
            };
            let joints: Vec<[u16; 4]> = joints.into_u16().collect();
            let weights: Vec<Vec4> = weights.into_f32().map(Vec4::from).collect();
            if joints.len() != count || weights.len() != count {
                return Err(format!(
                    "{label}: JOINTS_{set} / WEIGHTS_{set} are unreadable or their counts \
                     differ from POSITION"
                ));
            }
            if let Some(v) = weights
                .iter()
                .position(|w| !w.is_finite() || w.min_element() < 0.0)
            {
                return Err(format!(
                    "{label}: WEIGHTS_{set} of vertex {v} is {} (weights must be finite and \
                     not negative)",
                    weights[v]
                ));
            }
            if set == 0 {
                m.joints = joints;
                m.weights = weights;
            } else {
                m.joints1 = joints;
                m.weights1 = weights;
            }
        }
        if m.joints.is_empty() && !m.joints1.is_empty() {
            return Err(format!("{label}: JOINTS_1 without JOINTS_0"));
        }
        normalise_weights(self.conv.name, label, m);
        self.morph_targets(m)
    }

    fn morph_targets(&self, m: &mut Mesh) -> Result<(), String> {
        let (label, prim, reader) = (self.label, self.prim, self.reader);
        let count = m.positions.len();
        let targets = prim.morph_targets().len();
        if targets > MAX_MORPH_TARGETS {
            return Err(format!(
                "{label}: {targets} morph targets, at most {MAX_MORPH_TARGETS} are supported"
            ));
        }
        for (t, target) in prim.morph_targets().enumerate() {
            let accessors = [
                ("POSITION", target.positions()),
                ("NORMAL", target.normals()),
                ("TANGENT", target.tangents()),
            ];
            for (what, acc) in accessors {
                let Some(acc) = acc else { continue };
                let what = format!("{label} morph target {t} {what}");
                self.conv
                    .check_accessor(&what, &acc, &[Dimensions::Vec3], &[DataType::F32])?;
                if acc.count() != count {
                    return Err(format!(
                        "{what}: {} elements, POSITION has {count}",
                        acc.count()
                    ));
                }
            }
        }
        let has_base_tangents = prim.get(&Semantic::Tangents).is_some();
        for (t, (positions, normals, tangents)) in reader.read_morph_targets().enumerate() {
            let mut target = MorphTarget {
                positions: read_deltas(label, t, "POSITION", positions, count)?,
                normals: read_deltas(label, t, "NORMAL", normals, count)?,
                tangents: read_deltas(label, t, "TANGENT", tangents, count)?,
            };
            if !has_base_tangents && !target.tangents.is_empty() {
                // Displacements of tangents the file does not give (derived
                // tangents) have nothing to displace.
                target.tangents.clear();
            }
            m.morph_targets.push(target);
        }
        if m.morph_targets.len() != targets {
            return Err(format!(
                "{label}: read {} of {targets} morph targets",
                m.morph_targets.len()
            ));
        }
        m.morph_weights = vec![0.0; targets];
        if let Some(w) = self.mesh.weights() {
            if w.len() != targets {
                log::warn!(
                    "{}: {label}: mesh weights has {} entries for {targets} morph targets \
                     (missing ones are 0)",
                    self.conv.name,
                    w.len()
                );
            }
            for (d, &s) in m.morph_weights.iter_mut().zip(w) {
                *d = s;
            }
            if m.morph_weights.iter().any(|w| !w.is_finite()) {
                return Err(format!("{label}: mesh weights are not finite"));
            }
        }
        Ok(())
    }
}

impl Converter<'_> {
    /// The skin of an instance of `node` drawing scene mesh `mesh`: the node's
    /// skin when the mesh has joints (checked against the skin's joint count),
    /// else `None` (a skin on a mesh without joints is ignored with a warning).
    pub(super) fn instance_skin(
        &self,
        node: &gltf::Node,
        mesh: usize,
        name: &str,
    ) -> Result<Option<usize>, String> {
        let Some(skin) = node.skin() else {
            return Ok(None);
        };
        let mesh = &self.scene.meshes[mesh];
        if !mesh.is_skinned() {
            log::warn!(
                "{}: {name}: the node has skin {} but the mesh has no JOINTS_0/WEIGHTS_0; \
                 drawn unskinned",
                self.name,
                skin.index()
            );
            return Ok(None);
        }
        let joints = self
            .scene
            .skins
            .get(skin.index())
            .map_or(0, |s| s.joints.len());
        if let Some(j) = mesh.max_joint() {
            if j as usize >= joints {
                return Err(format!(
                    "{name}: mesh `{}` uses joint {j} but skin {} has {joints} joints",
                    mesh.name,
                    skin.index()
                ));
            }
        }
        Ok(Some(skin.index()))
    }
}

/// One attribute's displacements of morph target `t` (empty when absent),
/// checked: `count` finite vectors.
fn read_deltas(
    label: &str,
    t: usize,
    what: &str,
    it: Option<impl Iterator<Item = [f32; 3]>>,
    count: usize,
) -> Result<Vec<Vec3>, String> {
    let Some(it) = it else {
        return Ok(Vec::new());
    };
    let v: Vec<Vec3> = it.map(Vec3::from).collect();
    if v.len() != count {
        return Err(format!(
            "{label}: morph target {t} {what} is unreadable ({} of {count} elements)",
            v.len()
        ));
    }
    if let Some(i) = v.iter().position(|d| !d.is_finite()) {
        return Err(format!(
            "{label}: morph target {t} {what} of vertex {i} is not finite"
        ));
    }
    Ok(v)
}

/// Renormalises the 4 or 8 weights of every vertex to sum 1 and sets the joint
/// of every influence of weight 0 to 0.
fn normalise_weights(file: &str, label: &str, m: &mut Mesh) {
    if m.joints.is_empty() {
        return;
    }
    let eight = !m.joints1.is_empty();
    let mut zero = 0usize;
    for v in 0..m.joints.len() {
        let w1 = if eight { m.weights1[v] } else { Vec4::ZERO };
        let sum = m.weights[v].element_sum() + w1.element_sum();
        if sum > 0.0 {
            m.weights[v] /= sum;
            if eight {
                m.weights1[v] = w1 / sum;
            }
        } else {
            zero += 1;
            m.weights[v] = Vec4::X;
        }
        for k in 0..4 {
            if m.weights[v][k] == 0.0 {
                m.joints[v][k] = 0;
            }
            if eight && m.weights1[v][k] == 0.0 {
                m.joints1[v][k] = 0;
            }
        }
    }
    if zero > 0 {
        log::warn!(
            "{file}: {label}: {zero} vertices have skin weights that are all 0; they follow \
             their first joint"
        );
    }
}
