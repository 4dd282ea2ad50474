//! Scenes in time: glTF 2.0 keyframe animation, skins and morph targets, on the
//! CPU.
//!
//! - this file: the data ([`Animation`], [`Channel`], [`Sampler`], [`Skin`]) and
//!   what plays ([`Playback`]: which animations, looping or not);
//! - [`sample`]: keyframe interpolation (glTF 2.0 Appendix C: STEP, LINEAR with
//!   slerp for rotations, CUBICSPLINE);
//! - [`pose`]: [`Scene::pose`], the node hierarchy at a time → a [`Pose`]
//!   (instance world matrices, skin joint matrices, morph weights, lights and
//!   cameras);
//! - [`skin`]: the CPU reference of morphing and skinning vertices
//!   ([`Pose::skinned_mesh`]), the oracle of the GPU.
//!
//! The glTF reading is `crate::scene::gltf` (`animation.rs`, `skin_attributes.rs`).
//!
//! Time: all selected animations play on one clock, in seconds from 0; a channel
//! holds its first value before its first key and its last value after its last
//! key (glTF 2.0 §3.11: "output MUST be clamped to the nearest end of the input
//! range"). Looping wraps the clock at [`Scene::animation_duration`], so the whole
//! selection repeats together. Where two selected animations drive the same node
//! property, the later one in the file wins. Key times are `f32` as stored; the
//! clock and the segment arithmetic are `f64`.

pub mod cut;
pub mod pose;
pub mod sample;
pub mod skin;

pub use pose::{InstancePose, Pose};
pub use skin::PosedMesh;

use super::model::{Scene, SceneError};
use glam::Mat4;

/// Most joints one skin may have (the GPU keeps joint matrices in a storage
/// buffer; 256 covers common character rigs).
pub const MAX_JOINTS: usize = 256;
/// Most morph targets one mesh may have.
pub const MAX_MORPH_TARGETS: usize = 128;

/// How a sampler interpolates between keys (glTF `sampler.interpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// The value of the key at or before the time.
    Step,
    /// Linear; rotations by spherical linear interpolation on the shortest arc.
    Linear,
    /// Cubic Hermite spline; each key stores in-tangent, value, out-tangent.
    CubicSpline,
}

/// The node property a channel drives (glTF `channel.target.path`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChannelPath {
    Translation,
    Rotation,
    Scale,
    /// Morph-target weights of the node's mesh.
    Weights,
}

impl ChannelPath {
    /// The glTF name of the path.
    pub fn name(self) -> &'static str {
        match self {
            ChannelPath::Translation => "translation",
            ChannelPath::Rotation => "rotation",
            ChannelPath::Scale => "scale",
            ChannelPath::Weights => "weights",
        }
    }
}

/// Keyframes: times (seconds, strictly increasing, finite) and values.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampler {
    pub interpolation: Interpolation,
    pub times: Vec<f32>,
    /// Flattened values, [`Sampler::width`] floats per element: one element per
    /// key, or three (in-tangent, value, out-tangent) for CUBICSPLINE. Rotations
    /// are `x, y, z, w` quaternions.
    pub values: Vec<f32>,
}

impl Sampler {
    /// Floats per element (3 for translation and scale, 4 for rotation, the
    /// number of morph targets for weights); 0 when there are no keys.
    pub fn width(&self) -> usize {
        let elements = self.times.len() * self.elements_per_key();
        self.values.len().checked_div(elements).unwrap_or(0)
    }

    /// Elements stored per key: 3 for CUBICSPLINE, else 1.
    pub fn elements_per_key(&self) -> usize {
        match self.interpolation {
            Interpolation::CubicSpline => 3,
            _ => 1,
        }
    }

    /// The last key time (0 without keys).
    pub fn end(&self) -> f64 {
        self.times.last().map_or(0.0, |&t| t as f64)
    }
}

/// One animated node property.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The node ([`Scene::nodes`] index).
    pub node: usize,
    pub path: ChannelPath,
    pub sampler: Sampler,
}

/// A named set of channels (glTF `animation`).
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// The source's name, or `animation N`.
    pub name: String,
    pub channels: Vec<Channel>,
    /// The last key time of all channels, seconds (glTF times start at 0).
    pub duration: f64,
}

impl Animation {
    /// An animation whose duration is its channels' last key time.
    pub fn new(name: impl Into<String>, channels: Vec<Channel>) -> Animation {
        let duration = channels.iter().map(|c| c.sampler.end()).fold(0.0, f64::max);
        Animation {
            name: name.into(),
            channels,
            duration,
        }
    }
}

/// A skin (glTF `skin`): the joint nodes and their inverse bind matrices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Skin {
    pub name: String,
    /// Joint nodes ([`Scene::nodes`] indices); `JOINTS_n` index this list.
    pub joints: Vec<usize>,
    /// One per joint (identity where the source has none).
    pub inverse_bind_matrices: Vec<Mat4>,
    /// The skeleton root the source names, if any (informative only).
    pub skeleton: Option<usize>,
}

/// Which animations play.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Selection {
    /// Every animation of the scene, on one clock.
    #[default]
    All,
    /// None: the rest pose at every time.
    None,
    /// One animation ([`Scene::animations`] index).
    One(usize),
}

/// What plays and how: the selection and whether it loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Playback {
    pub selection: Selection,
    /// Wrap the clock at [`Scene::animation_duration`] (else hold the ends).
    pub looping: bool,
}

impl Playback {
    /// No animation (the rest pose at every time).
    pub fn none() -> Playback {
        Playback {
            selection: Selection::None,
            looping: false,
        }
    }

    /// Parses an `--animation` value against `scene`: `all`, `none` (any case), an
    /// index, or an animation's name (exact). An animation named like a keyword or
    /// a number is reached by its index. A miss lists the scene's animations.
    pub fn parse(spec: &str, scene: &Scene, looping: bool) -> Result<Playback, SceneError> {
        let err = |message: String| SceneError::Playback {
            spec: spec.to_string(),
            message,
        };
        let s = spec.trim();
        let selection = if s.eq_ignore_ascii_case("all") {
            Selection::All
        } else if s.eq_ignore_ascii_case("none") {
            Selection::None
        } else if let Ok(index) = s.parse::<usize>() {
            if index >= scene.animations.len() {
                return Err(err(format!(
                    "index {index} is out of range: {}",
                    list_animations(scene)
                )));
            }
            Selection::One(index)
        } else {
            match scene.animations.iter().position(|a| a.name == s) {
                Some(i) => Selection::One(i),
                None => {
                    return Err(err(format!(
                        "no animation of that name: {}",
                        list_animations(scene)
                    )))
                }
            }
        };
        Ok(Playback { selection, looping })
    }

    /// The animations that play, in the scene's order.
    pub fn animations<'a>(&self, scene: &'a Scene) -> &'a [Animation] {
        match self.selection {
            Selection::All => &scene.animations,
            Selection::None => &[],
            Selection::One(i) => scene.animations.get(i..=i).unwrap_or(&[]),
        }
    }

    /// The clock of the animations at `time` seconds: wrapped into
    /// `[0, duration)` when looping (and the duration is positive), else as is.
    pub fn local_time(&self, scene: &Scene, time: f64) -> f64 {
        let duration = scene.animation_duration(self);
        if self.looping && duration > 0.0 && time.is_finite() {
            time.rem_euclid(duration)
        } else {
            time
        }
    }
}

/// `the scene's animations: 0 `Walk`, 1 `Run`` or `the scene has no animations`.
fn list_animations(scene: &Scene) -> String {
    if scene.animations.is_empty() {
        return format!("{} has no animations", scene.name);
    }
    let names: Vec<String> = scene
        .animations
        .iter()
        .enumerate()
        .map(|(i, a)| format!("{i} `{}`", a.name))
        .collect();
    format!(
        "the animations of {} are {} (or all, none)",
        scene.name,
        names.join(", ")
    )
}

impl Scene {
    /// Whether any animation has a channel (a scene without is still: every time
    /// poses the rest pose).
    pub fn is_animated(&self) -> bool {
        self.animations.iter().any(|a| !a.channels.is_empty())
    }

    /// The longest duration of the animations `playback` selects, seconds (0 when
    /// none plays).
    pub fn animation_duration(&self, playback: &Playback) -> f64 {
        playback
            .animations(self)
            .iter()
            .map(|a| a.duration)
            .fold(0.0, f64::max)
    }

    /// Checks the animation data the pose and the renderer index with: node,
    /// skin and joint indices in range, the hierarchy a set of trees, sampler
    /// layouts, key times strictly increasing and values finite, skins within
    /// [`MAX_JOINTS`], morph targets and weights of matching sizes.
    pub(crate) fn validate_animation(&self) -> Result<(), SceneError> {
        let err = |message: String| SceneError::Animation {
            name: self.name.clone(),
            message,
        };
        super::node::check_hierarchy(&self.nodes, super::node::MAX_NODE_DEPTH).map_err(err)?;
        self.check_skins().map_err(err)?;
        self.check_instance_deformation().map_err(err)?;
        self.check_light_and_camera_nodes().map_err(err)?;
        self.check_channels().map_err(err)
    }

    /// Skins of at most [`MAX_JOINTS`] joints, an inverse bind matrix each,
    /// joints naming existing nodes.
    fn check_skins(&self) -> Result<(), String> {
        let node_count = self.nodes.len();
        for (si, skin) in self.skins.iter().enumerate() {
            if skin.joints.len() > MAX_JOINTS {
                return Err(format!(
                    "skin {si} (`{}`) has {} joints, at most {MAX_JOINTS} are supported",
                    skin.name,
                    skin.joints.len()
                ));
            }
            if skin.inverse_bind_matrices.len() != skin.joints.len() {
                return Err(format!(
                    "skin {si}: {} inverse bind matrices for {} joints",
                    skin.inverse_bind_matrices.len(),
                    skin.joints.len()
                ));
            }
            if let Some(&j) = skin.joints.iter().find(|&&j| j >= node_count) {
                return Err(format!("skin {si}: joint node {j} is out of range"));
            }
        }
        Ok(())
    }

    /// Instances on existing nodes, with a morph weight per morph target of
    /// their mesh and a skin that has every joint the mesh uses.
    fn check_instance_deformation(&self) -> Result<(), String> {
        let node_count = self.nodes.len();
        for (ii, inst) in self.instances.iter().enumerate() {
            let label = || format!("instance {ii} (`{}`)", inst.name);
            if inst.node.is_some_and(|n| n >= node_count) {
                return Err(format!("{}: node out of range", label()));
            }
            let Some(mesh) = self.meshes.get(inst.mesh) else {
                continue;
            };
            if inst.morph_weights.len() != mesh.morph_targets.len() {
                return Err(format!(
                    "{}: {} morph weights for {} morph targets",
                    label(),
                    inst.morph_weights.len(),
                    mesh.morph_targets.len()
                ));
            }
            if let Some(s) = inst.skin {
                let skin = self
                    .skins
                    .get(s)
                    .ok_or_else(|| format!("{}: skin {s} is out of range", label()))?;
                if let Some(j) = mesh.max_joint() {
                    if j as usize >= skin.joints.len() {
                        return Err(format!(
                            "{}: mesh `{}` uses joint {j}, skin {s} has {} joints",
                            label(),
                            mesh.name,
                            skin.joints.len()
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Lights and cameras on existing nodes.
    fn check_light_and_camera_nodes(&self) -> Result<(), String> {
        let node_count = self.nodes.len();
        for light in &self.lights {
            if light.node.is_some_and(|n| n >= node_count) {
                return Err(format!("light `{}`: node out of range", light.name));
            }
        }
        for cam in &self.cameras {
            if cam.node.is_some_and(|n| n >= node_count) {
                return Err(format!("camera `{}`: node out of range", cam.name));
            }
        }
        Ok(())
    }

    /// Channels animating existing nodes, with samplers of the path's width
    /// (the node's morph weights for `weights`).
    fn check_channels(&self) -> Result<(), String> {
        for (ai, anim) in self.animations.iter().enumerate() {
            for (ci, ch) in anim.channels.iter().enumerate() {
                let label = || format!("animation {ai} (`{}`) channel {ci}", anim.name);
                let node = self
                    .nodes
                    .get(ch.node)
                    .ok_or_else(|| format!("{}: node {} is out of range", label(), ch.node))?;
                let width = match ch.path {
                    ChannelPath::Translation | ChannelPath::Scale => 3,
                    ChannelPath::Rotation => 4,
                    ChannelPath::Weights => node.weights.len(),
                };
                check_sampler(&ch.sampler, width).map_err(|m| format!("{}: {m}", label()))?;
            }
        }
        Ok(())
    }
}

/// Checks a sampler's keys: at least one, finite and strictly increasing times,
/// `width` finite floats per element.
pub(crate) fn check_sampler(s: &Sampler, width: usize) -> Result<(), String> {
    if s.times.is_empty() {
        return Err("no keys".into());
    }
    if let Some(k) = s.times.iter().position(|t| !t.is_finite()) {
        return Err(format!("key time {k} is {} (not finite)", s.times[k]));
    }
    if let Some(k) = s.times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(format!(
            "key times are not strictly increasing: key {} at {} s follows key {k} at {} s",
            k + 1,
            s.times[k + 1],
            s.times[k]
        ));
    }
    let expected = s.times.len() * s.elements_per_key() * width;
    if width == 0 || s.values.len() != expected {
        return Err(format!(
            "{} values for {} keys ({} expected: {} per key)",
            s.values.len(),
            s.times.len(),
            expected,
            s.elements_per_key() * width
        ));
    }
    if let Some(i) = s.values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "value {} of key {} is {} (not finite)",
            i % width,
            i / (width * s.elements_per_key()),
            s.values[i]
        ));
    }
    Ok(())
}
