//! The scene model: meshes, instances, textures, random lights and the [`Scene`]
//! that holds them all.
//!
//! Units are whatever the source uses (glTF: metres). World space is right-handed,
//! +Y up. Colours are linear RGB.
//!
//! The scene's other parts have files of their own and are re-exported here: lights
//! (`light.rs`), cameras (`camera.rs`) and materials (`material.rs`).

pub use super::animation::{Animation, Skin};
pub use super::camera::{look_to_rh, perspective_rh, Camera, NamedCamera};
pub use super::error::{SceneError, MAX_MATERIALS};
pub use super::light::{Light, LightKind, ATTENUATION_THRESHOLD};
pub use super::material::{roughness_from_shininess, AlphaMode, Material, ShaderBinding};
pub use super::node::Node;
use glam::{Mat4, Vec2, Vec3, Vec4};

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Grows the box to contain `p`.
    pub fn add(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Whether nothing was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Length of the diagonal.
    pub fn diagonal(&self) -> f32 {
        (self.max - self.min).length()
    }

    /// The box of the 8 corners transformed by `m`.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        let mut out = Aabb::EMPTY;
        if self.is_empty() {
            return out;
        }
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out.add(m.transform_point3(c));
        }
        out
    }
}

/// Triangle geometry (one glTF primitive). All attribute arrays have the same length.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Unit normals (computed from the triangles when the source has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (set 0); zeros when the source has none.
    pub uvs: Vec<Vec2>,
    /// Texture coordinates, set 1 (`TEXCOORD_1`); empty when the source has none.
    pub uvs1: Vec<Vec2>,
    /// Linear vertex colours (`COLOR_0`); empty when the source has none.
    pub colors: Vec<Vec4>,
    /// Tangents (xyz, w = handedness ±1); `None` when there are neither source
    /// tangents nor UVs to derive them from (normal maps are then ignored).
    pub tangents: Option<Vec<Vec4>>,
    /// Triangle list, every index `< positions.len()`.
    pub indices: Vec<u32>,
    /// Whether the normals are face normals of unshared vertices ([`Mesh::make_flat`]):
    /// a deformed copy gets its face normals computed again.
    pub flat: bool,
    /// Skin joints of influences 1–4 (`JOINTS_0`), indices into the skin's joint
    /// list (0 where the weight is 0); empty when the mesh is not skinned.
    pub joints: Vec<[u16; 4]>,
    /// Skin weights of influences 1–4 (`WEIGHTS_0`); with [`Mesh::weights1`] they
    /// sum to 1 for every vertex. Empty when the mesh is not skinned.
    pub weights: Vec<Vec4>,
    /// Joints of influences 5–8 (`JOINTS_1`); empty for at most 4 influences.
    pub joints1: Vec<[u16; 4]>,
    /// Weights of influences 5–8 (`WEIGHTS_1`); empty for at most 4 influences.
    pub weights1: Vec<Vec4>,
    /// Morph targets (displacements added with the morph weights before skinning).
    pub morph_targets: Vec<MorphTarget>,
    /// The mesh's default morph weights (glTF `mesh.weights`, else zeros), one per
    /// morph target.
    pub morph_weights: Vec<f32>,
}

/// One morph target of a mesh: per-vertex displacements, each list empty when the
/// target does not displace that attribute, else as long as the positions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MorphTarget {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Tangent displacements (xyz; the handedness w is not displaced).
    pub tangents: Vec<Vec3>,
}

impl Mesh {
    /// Bounds of the positions.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &p in &self.positions {
            b.add(p);
        }
        b
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Whether the mesh has skin joints and weights.
    pub fn is_skinned(&self) -> bool {
        !self.joints.is_empty()
    }

    /// The largest joint index of an influence with a weight other than 0, if any.
    pub fn max_joint(&self) -> Option<u16> {
        let sets = [
            (&self.joints, &self.weights),
            (&self.joints1, &self.weights1),
        ];
        sets.iter()
            .flat_map(|(j, w)| j.iter().zip(w.iter()))
            .flat_map(|(j, w)| (0..4).filter(|&k| w[k] != 0.0).map(move |k| j[k]))
            .max()
    }

    /// Area-weighted vertex normals from the triangles.
    pub fn compute_normals(&mut self) {
        let mut n = vec![Vec3::ZERO; self.positions.len()];
        for t in self.indices.chunks_exact(3) {
            let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
            let fnrm = (self.positions[b] - self.positions[a])
                .cross(self.positions[c] - self.positions[a]);
            n[a] += fnrm;
            n[b] += fnrm;
            n[c] += fnrm;
        }
        self.normals = n
            .into_iter()
            .map(|v| v.try_normalize().unwrap_or(Vec3::Y))
            .collect();
    }

    /// Flat shading, as glTF requires for primitives without normals: every
    /// triangle gets its own three vertices (all attributes copied) with the
    /// face normal; tangents are dropped (derive them again if needed).
    pub fn make_flat(&mut self) {
        let idx = std::mem::take(&mut self.indices);
        fn gather<T: Copy>(v: &[T], idx: &[u32]) -> Vec<T> {
            idx.iter().map(|&i| v[i as usize]).collect()
        }
        self.positions = gather(&self.positions, &idx);
        if !self.uvs.is_empty() {
            self.uvs = gather(&self.uvs, &idx);
        }
        if !self.uvs1.is_empty() {
            self.uvs1 = gather(&self.uvs1, &idx);
        }
        if !self.colors.is_empty() {
            self.colors = gather(&self.colors, &idx);
        }
        for list in [&mut self.joints, &mut self.joints1] {
            if !list.is_empty() {
                *list = gather(list, &idx);
            }
        }
        for list in [&mut self.weights, &mut self.weights1] {
            if !list.is_empty() {
                *list = gather(list, &idx);
            }
        }
        for target in &mut self.morph_targets {
            for list in [
                &mut target.positions,
                &mut target.normals,
                &mut target.tangents,
            ] {
                if !list.is_empty() {
                    *list = gather(list, &idx);
                }
            }
            // glTF: without base normals the normal and tangent displacements
            // are ignored (flat normals are computed for the morphed shape).
            target.normals.clear();
            target.tangents.clear();
        }
        self.flat = true;
        self.tangents = None;
        self.normals = self
            .positions
            .chunks_exact(3)
            .flat_map(|t| {
                let n = (t[1] - t[0])
                    .cross(t[2] - t[0])
                    .try_normalize()
                    .unwrap_or(Vec3::Y);
                [n; 3]
            })
            .collect();
        self.indices = (0..self.positions.len() as u32).collect();
    }

    /// Per-vertex tangents from UV derivatives (accumulated per triangle,
    /// Gram-Schmidt orthogonalised against the normal), with the glTF handedness:
    /// the bitangent `cross(n, t) · w` points towards decreasing v.
    pub fn compute_tangents(&mut self) {
        let count = self.positions.len();
        let mut tan = vec![Vec3::ZERO; count];
        let mut bit = vec![Vec3::ZERO; count];
        for t in self.indices.chunks_exact(3) {
            let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
            let (e1, e2) = (
                self.positions[b] - self.positions[a],
                self.positions[c] - self.positions[a],
            );
            let (d1, d2) = (self.uvs[b] - self.uvs[a], self.uvs[c] - self.uvs[a]);
            let det = d1.x * d2.y - d2.x * d1.y;
            if det.abs() < 1e-12 {
                continue;
            }
            let r = 1.0 / det;
            let t_dir = (e1 * d2.y - e2 * d1.y) * r;
            let b_dir = (e2 * d1.x - e1 * d2.x) * r;
            for &i in &[a, b, c] {
                tan[i] += t_dir;
                bit[i] += b_dir;
            }
        }
        let tangents = (0..count)
            .map(|i| {
                let n = self.normals[i];
                let t = (tan[i] - n * n.dot(tan[i])).try_normalize();
                match t {
                    Some(t) => {
                        // glTF: bitangent = cross(n, t) · w points to image "up"
                        // (+Y of a normal map), which is decreasing v, since v
                        // grows downwards in glTF texture space.
                        let w = if n.cross(t).dot(bit[i]) > 0.0 {
                            -1.0
                        } else {
                            1.0
                        };
                        t.extend(w)
                    }
                    None => Vec4::ZERO,
                }
            })
            .collect();
        self.tangents = Some(tangents);
    }
}

/// One placement of a mesh with a material.
#[derive(Debug, Clone, Default)]
pub struct Instance {
    pub name: String,
    pub mesh: usize,
    pub material: usize,
    /// Object-to-world transform (in the rest pose, for an instance of a node).
    pub transform: Mat4,
    /// The node that places it ([`Scene::nodes`]); `None` for an instance placed
    /// by [`Instance::transform`] alone (built-in scenes), which never moves.
    pub node: Option<usize>,
    /// The skin deforming it ([`Scene::skins`]), if the node has one and the mesh
    /// has joints and weights.
    pub skin: Option<usize>,
    /// Rest morph weights, one per morph target of the mesh (glTF `node.weights`,
    /// else `mesh.weights`, else zeros).
    pub morph_weights: Vec<f32>,
}

/// An RGBA8 texture image (the bytes as stored: sRGB for colour textures, linear for
/// normal maps; the material says how each is used).
#[derive(Debug, Clone)]
pub struct TextureImage {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// A scene ready to render.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Where it came from (file path or `builtin:NAME`), for messages.
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
    pub instances: Vec<Instance>,
    pub lights: Vec<Light>,
    pub cameras: Vec<NamedCamera>,
    /// Linear colour of pixels without geometry.
    pub background: Vec3,
    /// The node hierarchy (glTF nodes, by index); empty for built-in scenes.
    pub nodes: Vec<Node>,
    /// Skins, referenced by [`Instance::skin`].
    pub skins: Vec<Skin>,
    /// Keyframe animations of the nodes ([`crate::scene::animation`]).
    pub animations: Vec<Animation>,
    /// The light of the world around the scene (`None`: its lights only); see
    /// [`Scene::set_environment`].
    pub environment: Option<super::environment::Environment>,
}

impl Scene {
    /// Whether instance `i` changes shape over time (a skin, or morph targets):
    /// the renderer gives it vertices of its own, rewritten per frame from
    /// [`crate::scene::Pose::deformed_mesh`].
    pub fn is_deformed(&self, i: usize) -> bool {
        let inst = &self.instances[i];
        inst.skin.is_some()
            || self
                .meshes
                .get(inst.mesh)
                .is_some_and(|m| !m.morph_targets.is_empty())
    }

    /// World bounds of all instances.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        let mesh_bounds: Vec<Aabb> = self.meshes.iter().map(Mesh::bounds).collect();
        for inst in &self.instances {
            if let Some(mb) = mesh_bounds.get(inst.mesh) {
                let t = mb.transformed(&inst.transform);
                if !t.is_empty() {
                    b.add(t.min);
                    b.add(t.max);
                }
            }
        }
        b
    }

    /// Triangles drawn per frame (over all instances).
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes.get(i.mesh).map_or(0, Mesh::triangle_count))
            .sum()
    }

    /// The first scene camera, else [`Camera::framing`] of the bounds.
    pub fn default_camera(&self) -> Camera {
        self.cameras
            .first()
            .map(|c| c.camera)
            .unwrap_or_else(|| Camera::framing(&self.bounds()))
    }

    /// Near and far planes that enclose the scene bounds as seen from `cam`.
    pub fn fit_clip(&self, cam: &Camera) -> (f32, f32) {
        let b = self.bounds();
        if b.is_empty() {
            return (0.1, 100.0);
        }
        let radius = b.diagonal() * 0.5;
        let dir = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
        let center_dist = (b.center() - cam.eye).dot(dir);
        let far = (center_dist + radius * 1.1).max(radius * 0.01);
        let near = (center_dist - radius * 1.1).max(far * 1e-4);
        (near, far)
    }

    /// The lights used when a scene has none: a white directional key light from
    /// above-front-left (direction (−0.4, −1, −0.6)) of π lux, under which a white
    /// Lambertian surface facing it has radiance 1, plus white ambient light of
    /// radiance 0.15. A scene with lights of its own gets none of these.
    pub fn default_lights() -> Vec<Light> {
        vec![
            Light {
                name: "default key light".into(),
                ..Light::directional(Vec3::new(-0.4, -1.0, -0.6), Vec3::ONE, std::f32::consts::PI)
            },
            Light {
                name: "default ambient".into(),
                ..Light::ambient(Vec3::ONE, 0.15)
            },
        ]
    }

    /// Adds [`Scene::default_lights`] when the scene has no lights.
    pub fn ensure_lights(&mut self) {
        if self.lights.is_empty() {
            log::warn!(
                "{}: no lights in the scene; adding the default key light (π lux) and ambient (0.15)",
                self.name
            );
            self.lights = Scene::default_lights();
        }
    }

    /// Adds `n` point lights (the deferred-rendering course notes): a position uniformly inside the scene bounds,
    /// a radius between 4 % and 10 % of the bounds' diagonal, a saturated random hue
    /// and intensity 1, casting no shadows. Deterministic for a seed (own xorshift
    /// PRNG).
    pub fn add_random_point_lights(&mut self, n: usize, seed: u64) {
        self.add_random_point_lights_sized(n, seed, 0.04, 0.10);
    }

    /// Like [`Scene::add_random_point_lights`] with the radius range given as
    /// fractions of the bounds' diagonal.
    pub fn add_random_point_lights_sized(
        &mut self,
        n: usize,
        seed: u64,
        min_radius: f32,
        max_radius: f32,
    ) {
        let b = self.bounds();
        let (lo, hi) = if b.is_empty() {
            (Vec3::splat(-1.0), Vec3::splat(1.0))
        } else {
            (b.min, b.max)
        };
        let diag = (hi - lo).length().max(1e-3);
        let mut rng = Rng::new(seed);
        for i in 0..n {
            let p = Vec3::new(
                lo.x + (hi.x - lo.x) * rng.next_f32(),
                lo.y + (hi.y - lo.y) * rng.next_f32(),
                lo.z + (hi.z - lo.z) * rng.next_f32(),
            );
            let radius = diag * (min_radius + (max_radius - min_radius) * rng.next_f32());
            let color = hue_to_rgb(rng.next_f32());
            self.lights.push(Light {
                name: format!("random point {i}"),
                // benchmark lights (light-count scaling): no shadow maps
                casts_shadows: false,
                ..Light::point(p, color, 1.0, radius)
            });
        }
    }

    /// Checks the invariants the renderer relies on.
    pub fn validate(&self) -> Result<(), SceneError> {
        if self.materials.len() > MAX_MATERIALS {
            return Err(SceneError::TooManyMaterials {
                name: self.name.clone(),
                count: self.materials.len(),
            });
        }
        if self.triangle_count() == 0 {
            return Err(SceneError::Empty(self.name.clone()));
        }
        self.validate_animation()
    }
}

/// A saturated colour of hue `h` in [0, 1).
fn hue_to_rgb(h: f32) -> Vec3 {
    let h6 = (h.fract() * 6.0).min(5.9999);
    let x = 1.0 - (h6 % 2.0 - 1.0).abs();
    match h6 as u32 {
        0 => Vec3::new(1.0, x, 0.0),
        1 => Vec3::new(x, 1.0, 0.0),
        2 => Vec3::new(0.0, 1.0, x),
        3 => Vec3::new(0.0, x, 1.0),
        4 => Vec3::new(x, 0.0, 1.0),
        _ => Vec3::new(1.0, 0.0, x),
    }
}

/// A small deterministic PRNG (xorshift64*, seeded through splitmix64).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        Rng((z ^ (z >> 31)) | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_meshes_have_face_normals_and_own_vertices() {
        let mut m = crate::scene::builtin::icosphere(1);
        let tris = m.triangle_count();
        m.make_flat();
        assert_eq!(m.positions.len(), tris * 3);
        assert_eq!(m.normals.len(), tris * 3);
        for (t, n) in m.positions.chunks_exact(3).zip(m.normals.chunks_exact(3)) {
            let face = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            assert!(n.iter().all(|v| (*v - face).length() < 1e-5));
        }
    }

    #[test]
    fn derived_tangents_follow_the_gltf_convention() {
        // The built-in plane's hand-written frame: t = +X (increasing u), and the
        // bitangent cross(+Y, +X) = -Z points to decreasing v (v grows with z).
        let mut m = crate::scene::builtin::grid_plane(2);
        let given = m.tangents.clone().unwrap();
        m.compute_tangents();
        for (a, b) in given.iter().zip(m.tangents.as_ref().unwrap()) {
            assert!((*a - *b).length() < 1e-5, "{a} vs {b}");
        }
        // and image-up (decreasing v) is the bitangent's direction
        let t = m.tangents.as_ref().unwrap()[0];
        let b = m.normals[0].cross(t.truncate()) * t.w;
        assert!(b.dot(Vec3::NEG_Z) > 0.99, "{b}");
    }

    #[test]
    fn rng_is_deterministic() {
        let a: Vec<u64> = {
            let mut r = Rng::new(7);
            (0..4).map(|_| r.next_u64()).collect()
        };
        let b: Vec<u64> = {
            let mut r = Rng::new(7);
            (0..4).map(|_| r.next_u64()).collect()
        };
        assert_eq!(a, b);
        let mut r = Rng::new(1);
        assert!((0..1000).all(|_| (0.0..1.0).contains(&r.next_f32())));
    }
}
