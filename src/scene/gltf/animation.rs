//! glTF skins and animations, read and checked (glTF 2.0 §3.7.3 "Skins", §3.11
//! "Animations").
//!
//! Every problem is an error naming the skin, or the animation and channel: a
//! channel whose node does not exist, accessors of the wrong type or outside their
//! buffers, key times that are not finite or not strictly increasing, output
//! counts that do not match the keys (× 3 for CUBICSPLINE, × the morph targets
//! for weights), non-finite values, zero rotation keys, `weights` channels on
//! nodes without morph targets, skins of more than [`MAX_JOINTS`] joints or with
//! too few inverse bind matrices. Rotation keys that are not unit length (quantised
//! files) are normalised. A node given by a
//! `matrix` that a channel animates (glTF forbids it) is decomposed into TRS with
//! a warning.

use super::Converter;
use crate::scene::animation::{
    check_sampler, Animation, Channel, ChannelPath, Interpolation, Sampler, Skin, MAX_JOINTS,
};
use crate::scene::node::NodeTransform;
use glam::{Mat4, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::util::ReadOutputs;
use std::collections::HashSet;

impl Converter<'_> {
    /// Every skin of the document, by glTF index.
    pub(super) fn skins(&self, doc: &gltf::Document) -> Result<Vec<Skin>, String> {
        let buffers = self.buffers;
        let mut out = Vec::new();
        for skin in doc.skins() {
            let name = skin
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("skin {}", skin.index()));
            let label = format!("skin {} (`{name}`)", skin.index());
            let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
            if joints.len() > MAX_JOINTS {
                return Err(format!(
                    "{label}: {} joints, at most {MAX_JOINTS} are supported",
                    joints.len()
                ));
            }
            let inverse_bind_matrices = match skin.inverse_bind_matrices() {
                None => vec![Mat4::IDENTITY; joints.len()],
                Some(acc) => {
                    self.check_accessor(
                        &format!("{label} inverseBindMatrices"),
                        &acc,
                        &[Dimensions::Mat4],
                        &[DataType::F32],
                    )?;
                    if acc.count() < joints.len() {
                        return Err(format!(
                            "{label}: {} inverse bind matrices for {} joints",
                            acc.count(),
                            joints.len()
                        ));
                    }
                    let reader = skin.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                    let m: Vec<Mat4> = reader
                        .read_inverse_bind_matrices()
                        .ok_or_else(|| format!("{label}: inverseBindMatrices are unreadable"))?
                        .take(joints.len())
                        .map(|m| Mat4::from_cols_array_2d(&m))
                        .collect();
                    if m.len() != joints.len() {
                        return Err(format!("{label}: inverseBindMatrices are unreadable"));
                    }
                    if let Some(i) = m.iter().position(|m| !m.is_finite()) {
                        return Err(format!("{label}: inverse bind matrix {i} is not finite"));
                    }
                    m
                }
            };
            out.push(Skin {
                name,
                joints,
                inverse_bind_matrices,
                skeleton: skin.skeleton().map(|n| n.index()),
            });
        }
        Ok(out)
    }

    /// Every animation of the document (after the nodes are read: `weights`
    /// channels take their width from the node's morph targets).
    pub(super) fn animations(&mut self, doc: &gltf::Document) -> Result<Vec<Animation>, String> {
        let json = doc.as_json();
        let node_count = self.scene.nodes.len();
        let mut out = Vec::new();
        for anim in doc.animations() {
            let ai = anim.index();
            let name = anim
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("animation {ai}"));
            let which = match anim.name() {
                Some(n) => format!("animation {ai} (`{n}`)"),
                None => format!("animation {ai}"),
            };
            let mut channels = Vec::new();
            let mut targets = HashSet::new();
            for (ci, channel) in anim.channels().enumerate() {
                // The `gltf` crate validates neither channel targets' node
                // indices nor their paths (and panics on a bad one), so both are
                // read from the JSON.
                let target = &json.animations[ai].channels[ci].target;
                let node = target.node.value();
                use gltf::json::validation::Checked;
                let path = match target.path {
                    Checked::Valid(gltf::animation::Property::Translation) => {
                        ChannelPath::Translation
                    }
                    Checked::Valid(gltf::animation::Property::Rotation) => ChannelPath::Rotation,
                    Checked::Valid(gltf::animation::Property::Scale) => ChannelPath::Scale,
                    Checked::Valid(gltf::animation::Property::MorphTargetWeights) => {
                        ChannelPath::Weights
                    }
                    Checked::Invalid => {
                        return Err(format!(
                            "{which} channel {ci}: the target path is not \
                             translation, rotation, scale or weights"
                        ))
                    }
                };
                let label = format!("{which} channel {ci} ({} of node {node})", path.name());
                if node >= node_count {
                    return Err(format!(
                        "{label}: node {node} does not exist (the file has {node_count} nodes)"
                    ));
                }
                let sampler = self
                    .channel_sampler(&label, &channel, path, node)
                    .map_err(|m| format!("{label}: {m}"))?;
                if !targets.insert((node, path)) {
                    log::warn!(
                        "{}: {label}: a second channel for the same target (the later wins)",
                        self.name
                    );
                }
                if path != ChannelPath::Weights {
                    let n = &mut self.scene.nodes[node];
                    if let NodeTransform::Matrix(_) = n.rest {
                        log::warn!(
                            "{}: {label}: the node is given by a matrix, which glTF forbids on \
                             animated nodes; using its decomposition into TRS",
                            self.name
                        );
                        let (translation, rotation, scale) = n.rest.trs();
                        n.rest = NodeTransform::Trs {
                            translation,
                            rotation,
                            scale,
                        };
                    }
                }
                channels.push(Channel {
                    node,
                    path,
                    sampler,
                });
            }
            out.push(Animation::new(name, channels));
        }
        Ok(out)
    }

    /// A channel's keys, checked (the message is prefixed with the channel).
    fn channel_sampler(
        &self,
        label: &str,
        channel: &gltf::animation::Channel,
        path: ChannelPath,
        node: usize,
    ) -> Result<Sampler, String> {
        let sampler = channel.sampler();
        let interpolation = match sampler.interpolation() {
            gltf::animation::Interpolation::Step => Interpolation::Step,
            gltf::animation::Interpolation::Linear => Interpolation::Linear,
            gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
        };
        let input = sampler.input();
        self.check_accessor(
            &format!("{label} input"),
            &input,
            &[Dimensions::Scalar],
            &[DataType::F32],
        )?;
        let normalised = [
            DataType::F32,
            DataType::I8,
            DataType::U8,
            DataType::I16,
            DataType::U16,
        ];
        let (dims, types, width): (Dimensions, &[DataType], usize) = match path {
            ChannelPath::Translation | ChannelPath::Scale => {
                (Dimensions::Vec3, &[DataType::F32], 3)
            }
            ChannelPath::Rotation => (Dimensions::Vec4, &normalised, 4),
            ChannelPath::Weights => {
                let targets = self.scene.nodes[node].weights.len();
                if targets == 0 {
                    return Err(
                        "the node has no mesh with morph targets (glTF: such nodes must not be \
                         targeted by `weights`)"
                            .into(),
                    );
                }
                (Dimensions::Scalar, &normalised, targets)
            }
        };
        self.check_accessor(
            &format!("{label} output"),
            &sampler.output(),
            &[dims],
            types,
        )?;
        let buffers = self.buffers;
        let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let times: Vec<f32> = reader
            .read_inputs()
            .ok_or("the key times are unreadable")?
            .collect();
        if times.len() != input.count() {
            return Err("the key times are unreadable".into());
        }
        let values: Vec<f32> = match reader.read_outputs().ok_or("the values are unreadable")? {
            ReadOutputs::Translations(it) | ReadOutputs::Scales(it) => it.flatten().collect(),
            ReadOutputs::Rotations(it) => it.into_f32().flatten().collect(),
            ReadOutputs::MorphTargetWeights(it) => it.into_f32().collect(),
        };
        let mut s = Sampler {
            interpolation,
            times,
            values,
        };
        check_sampler(&s, width)?;
        if path == ChannelPath::Rotation {
            normalise_rotation_keys(&mut s)?;
        }
        Ok(s)
    }
}

/// Normalises the value quaternions of a rotation sampler (not the CUBICSPLINE
/// tangents); a zero quaternion is an error.
fn normalise_rotation_keys(s: &mut Sampler) -> Result<(), String> {
    let per_key = s.elements_per_key();
    let value = if per_key == 3 { 1 } else { 0 };
    for k in 0..s.times.len() {
        let i = (k * per_key + value) * 4;
        let q = Vec4::from_slice(&s.values[i..i + 4]);
        // Unit keys are used as stored (Appendix C: "as-is").
        if (q.length_squared() - 1.0).abs() <= 1e-6 {
            continue;
        }
        let n = q
            .try_normalize()
            .ok_or_else(|| format!("rotation key {k} is the zero quaternion"))?;
        n.write_to_slice(&mut s.values[i..i + 4]);
    }
    Ok(())
}
