//! The scene model: meshes, instances, materials, textures, lights and cameras.
//!
//! Units are whatever the source uses (glTF: metres). World space is right-handed,
//! +Y up. Colours are linear RGB.

use glam::{Mat4, Vec2, Vec3, Vec4};
use std::fmt;

/// Attenuation threshold ε: a point or spot light's volume ends where
/// `intensity · max(colour) · f(d)` with `f(d) = 1 / (a + b·d + c·d²)` (seed 001,
/// eq. 2) falls to `ε = 1/256` (one 8-bit step at white). Shading uses the same
/// cut-off, so every technique lights exactly the same points.
pub const ATTENUATION_THRESHOLD: f32 = 1.0 / 256.0;

/// Most materials a scene may have: the material id is stored in 8 bits.
pub const MAX_MATERIALS: usize = 256;

/// Errors of building, loading or querying a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A glTF file could not be loaded; the message says why.
    #[error("{path}: {message}")]
    Gltf { path: String, message: String },
    /// `builtin:NAME` with an unknown NAME.
    #[error("unknown built-in scene `{0}` (available: builtin:room, builtin:bench)")]
    UnknownBuiltin(String),
    /// A `--camera` spec that does not parse or names no camera.
    #[error("camera `{spec}`: {message}")]
    Camera { spec: String, message: String },
    /// The scene has nothing to draw.
    #[error("{0}: the scene has no triangles to draw")]
    Empty(String),
    /// More than [`MAX_MATERIALS`] materials.
    #[error(
        "{name}: {count} materials, at most {MAX_MATERIALS} are supported (8-bit material id)"
    )]
    TooManyMaterials { name: String, count: usize },
}

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

    /// Per-vertex tangents from UV derivatives (accumulated per triangle,
    /// Gram-Schmidt orthogonalised against the normal).
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
                        let w = if n.cross(t).dot(bit[i]) < 0.0 {
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
#[derive(Debug, Clone)]
pub struct Instance {
    pub name: String,
    pub mesh: usize,
    pub material: usize,
    /// Object-to-world transform.
    pub transform: Mat4,
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

/// How a material's alpha is used (glTF `alphaMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AlphaMode {
    /// Alpha ignored.
    #[default]
    Opaque,
    /// Fragments with alpha below the cut-off are discarded; drawn deferred.
    Mask,
    /// Blended; drawn forward after composition, sorted back to front.
    Blend,
}

/// A material (seed 003, section 2): a *surface shader* that computes the
/// surface's colours, normal, roughness, emission and coverage, and a *lighting
/// shader* that turns one light into reflected diffuse and specular light. Both are
/// WGSL files (`shaders/materials/*.wgsl` or the user's) with the parameter values
/// and textures given here; the renderer generates every full shader from them
/// (see `docs/materials.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub surface: ShaderBinding,
    pub lighting: ShaderBinding,
    pub alpha_mode: AlphaMode,
    /// Coverage below which MASK fragments are discarded.
    pub alpha_cutoff: f32,
    /// Both faces are drawn; back faces see the flipped normal.
    pub double_sided: bool,
}

/// A material shader with its settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ShaderBinding {
    /// The shader's name: `standard`, `triplanar`, `lambert`, `phong`,
    /// `blinn_phong`, `cook_torrance`, or a user's `NAME` (`NAME.wgsl`).
    pub shader: String,
    /// The folder a user's shader is looked up in first (the material file's).
    pub dir: Option<std::path::PathBuf>,
    /// Parameter values by uniform field name (numbers; vectors as several).
    pub params: Vec<(String, Vec<f64>)>,
    /// Textures by the shader's texture variable name: indices into
    /// [`Scene::textures`].
    pub textures: Vec<(String, usize)>,
}

impl ShaderBinding {
    /// A shader with no settings (its defaults).
    pub fn new(shader: &str) -> ShaderBinding {
        ShaderBinding {
            shader: shader.to_string(),
            ..Default::default()
        }
    }

    /// Sets parameter `name` (replacing an earlier value).
    pub fn set(&mut self, name: &str, value: &[f64]) -> &mut Self {
        self.params.retain(|(n, _)| n != name);
        self.params.push((name.to_string(), value.to_vec()));
        self
    }

    /// Builder form of [`ShaderBinding::set`].
    pub fn with(mut self, name: &str, value: &[f64]) -> Self {
        self.set(name, value);
        self
    }

    /// Binds texture variable `name` to scene texture `index`.
    pub fn set_texture(&mut self, name: &str, index: usize) -> &mut Self {
        self.textures.retain(|(n, _)| n != name);
        self.textures.push((name.to_string(), index));
        self
    }

    /// The value set for `name`, if any.
    pub fn param(&self, name: &str) -> Option<&[f64]> {
        self.params
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The scene texture bound to `name`, if any.
    pub fn texture(&self, name: &str) -> Option<usize> {
        self.textures
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| *t)
    }
}

impl Material {
    /// A material of `surface` and `lighting` shaders, opaque and one-sided.
    pub fn new(name: &str, surface: ShaderBinding, lighting: ShaderBinding) -> Material {
        Material {
            name: name.to_string(),
            surface,
            lighting,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
        }
    }

    /// The standard surface with a diffuse colour and a grey specular reflectance
    /// `specular` (F0), lit by the paper's Phong model with exponent `shininess`
    /// (`SPECULAR_POWER`).
    pub fn phong(name: &str, diffuse: Vec3, specular: f32, shininess: f32) -> Material {
        let s = f64::from(specular.clamp(0.0, 1.0));
        let c = diffuse.to_array().map(f64::from);
        Material::new(
            name,
            ShaderBinding::new("standard")
                .with("base_color", &[c[0], c[1], c[2], 1.0])
                .with("specular", &[s, s, s])
                .with("metallic", &[0.0])
                .with(
                    "roughness",
                    &[f64::from(roughness_from_shininess(shininess))],
                ),
            ShaderBinding::new("phong")
                .with("specular_power", &[f64::from(shininess.clamp(1.0, 4096.0))]),
        )
    }

    /// glTF 2.0 metallic-roughness: the standard surface with these factors, lit by
    /// Cook-Torrance (GGX, height-correlated Smith, Schlick) as in the glTF
    /// specification's Appendix B.
    pub fn metallic_roughness(
        name: &str,
        base_color: Vec4,
        metallic: f32,
        roughness: f32,
    ) -> Material {
        Material::new(
            name,
            ShaderBinding::new("standard")
                .with("base_color", &base_color.to_array().map(f64::from))
                .with("metallic", &[f64::from(metallic.clamp(0.0, 1.0))])
                .with("roughness", &[f64::from(roughness.clamp(0.0, 1.0))]),
            ShaderBinding::new("cook_torrance"),
        )
    }

    /// The surface's `name` parameter as up to four floats (`default` where unset).
    pub fn surface_param(&self, name: &str, default: [f32; 4]) -> [f32; 4] {
        let mut out = default;
        if let Some(v) = self.surface.param(name) {
            for (o, x) in out.iter_mut().zip(v) {
                *o = *x as f32;
            }
        }
        out
    }
}

/// Perceptual roughness with the highlight width of a Phong exponent: the usual
/// Beckmann-to-Phong mapping `α = 2 / r⁴ − 2` inverted (α_beckmann = r²).
pub fn roughness_from_shininess(shininess: f32) -> f32 {
    (2.0 / (shininess.max(1.0) + 2.0))
        .powf(0.25)
        .clamp(0.0, 1.0)
}

/// The kind of a light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightKind {
    /// Constant light on every surface (`k_a · L_a`), a full-screen pass.
    Ambient,
    /// Parallel light along [`Light::direction`], a full-screen pass.
    Directional,
    /// Omnidirectional light at [`Light::position`], a sphere volume.
    Point,
    /// Cone of light from [`Light::position`] along [`Light::direction`]; full
    /// intensity inside `inner` and zero outside `outer` (half-angles, radians);
    /// a cone volume.
    Spot { inner: f32, outer: f32 },
}

/// A light. Point and spot lights fall off with `f(d) = 1 / (a + b·d + c·d²)` and
/// end at [`Light::radius`].
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Linear colour; multiplied by `intensity`.
    pub color: Vec3,
    pub intensity: f32,
    /// World position (point, spot).
    pub position: Vec3,
    /// World direction the light travels (directional, spot), unit length.
    pub direction: Vec3,
    /// `[a, b, c]` of the attenuation `1 / (a + b·d + c·d²)`.
    pub attenuation: [f32; 3],
    /// Hard upper bound of the radius (glTF `range`), if any.
    pub range: Option<f32>,
}

impl Light {
    /// A point light whose volume radius is exactly `radius`: `a = 1`, `b = 0` and
    /// `c` chosen so that `intensity · max(colour) · f(radius) = ε`.
    pub fn point(position: Vec3, color: Vec3, intensity: f32, radius: f32) -> Light {
        let peak = intensity * color.max_element();
        let c = ((peak / ATTENUATION_THRESHOLD - 1.0) / (radius * radius)).max(1e-6);
        Light {
            name: "point".into(),
            kind: LightKind::Point,
            color,
            intensity,
            position,
            direction: Vec3::NEG_Y,
            attenuation: [1.0, 0.0, c],
            range: None,
        }
    }

    /// A spot light with the same falloff as [`Light::point`] (`radius` = length of
    /// the cone) and the given half-angles in radians.
    pub fn spot(
        position: Vec3,
        direction: Vec3,
        color: Vec3,
        intensity: f32,
        radius: f32,
        inner: f32,
        outer: f32,
    ) -> Light {
        Light {
            name: "spot".into(),
            kind: LightKind::Spot { inner, outer },
            direction: direction.normalize_or(Vec3::NEG_Y),
            ..Light::point(position, color, intensity, radius)
        }
    }

    /// A directional light travelling along `direction`.
    pub fn directional(direction: Vec3, color: Vec3, intensity: f32) -> Light {
        Light {
            name: "directional".into(),
            kind: LightKind::Directional,
            color,
            intensity,
            position: Vec3::ZERO,
            direction: direction.normalize_or(Vec3::NEG_Y),
            attenuation: [1.0, 0.0, 0.0],
            range: None,
        }
    }

    /// Ambient light.
    pub fn ambient(color: Vec3, intensity: f32) -> Light {
        Light {
            name: "ambient".into(),
            kind: LightKind::Ambient,
            ..Light::directional(Vec3::NEG_Y, color, intensity)
        }
    }

    /// Whether the light has a bounded volume (point, spot).
    pub fn is_local(&self) -> bool {
        matches!(self.kind, LightKind::Point | LightKind::Spot { .. })
    }

    /// The distance where the attenuated intensity falls to [`ATTENUATION_THRESHOLD`]
    /// (solving `a + b·d + c·d² = I·max(colour)/ε`), capped by [`Light::range`];
    /// infinite for directional and ambient lights, 0 for a light too weak to reach
    /// the threshold anywhere.
    pub fn radius(&self) -> f32 {
        if !self.is_local() {
            return f32::INFINITY;
        }
        let [a, b, c] = self.attenuation;
        let peak = self.intensity * self.color.max_element();
        let k = peak / ATTENUATION_THRESHOLD;
        let r = if k <= a || !k.is_finite() {
            0.0
        } else if c > 0.0 {
            let disc = b * b + 4.0 * c * (k - a);
            (-b + disc.sqrt()) / (2.0 * c)
        } else if b > 0.0 {
            (k - a) / b
        } else {
            f32::INFINITY
        };
        match self.range {
            Some(range) if range > 0.0 => r.min(range),
            _ => r,
        }
    }
}

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// World-to-view matrix (right-handed, looking down −Z).
    pub fn view(&self) -> Mat4 {
        let dir = (self.target - self.eye).normalize_or(Vec3::NEG_Z);
        let up = if dir.cross(self.up).length_squared() < 1e-10 {
            if dir.y.abs() > 0.9 {
                Vec3::Z
            } else {
                Vec3::Y
            }
        } else {
            self.up
        };
        look_to_rh(self.eye, dir, up)
    }

    /// Projection with depth 0 (near) .. 1 (far), as wgpu uses.
    pub fn proj(&self, aspect: f32) -> Mat4 {
        perspective_rh(self.fov_y, aspect, self.near, self.far)
    }

    /// The camera as the effect runtime's standard values.
    pub fn camera_std(&self, aspect: f32) -> crate::gpu::executor::CameraStd {
        let proj = self.proj(aspect);
        crate::gpu::executor::CameraStd {
            near: self.near,
            far: self.far,
            proj: proj.to_cols_array(),
            inv_proj: proj.inverse().to_cols_array(),
        }
    }

    /// A camera in front of (+Z) and above the box, framing its bounding sphere with
    /// a 60° vertical field of view.
    pub fn framing(bounds: &Aabb) -> Camera {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (bounds.diagonal() * 0.5).max(1e-3))
        };
        let fov_y = 60f32.to_radians();
        let dist = radius / (fov_y * 0.5).sin() * 1.05;
        let dir = Vec3::new(0.0, 0.35, 1.0).normalize();
        let eye = center + dir * dist;
        Camera {
            eye,
            target: center,
            up: Vec3::Y,
            fov_y,
            near: ((dist - radius) * 0.5).max(radius * 1e-3),
            far: dist + radius * 2.0,
        }
    }

    /// Parses a `--camera` spec against `scene`:
    /// - a number: the glTF camera with that index ([`Scene::cameras`]);
    /// - `key=value` pairs separated by `;`: `eye=x,y,z`, `target=x,y,z`, `up=x,y,z`,
    ///   `fov=DEGREES` (vertical), `near=N`, `far=F`; missing keys come from the
    ///   scene's default camera (target defaults to the scene centre when only the
    ///   eye is given, near/far are refitted to the scene bounds);
    /// - otherwise the name of a scene camera.
    pub fn parse_spec(spec: &str, scene: &Scene) -> Result<Camera, SceneError> {
        let err = |message: String| SceneError::Camera {
            spec: spec.to_string(),
            message,
        };
        let s = spec.trim();
        if let Ok(index) = s.parse::<usize>() {
            return scene.cameras.get(index).map(|c| c.camera).ok_or_else(|| {
                err(format!(
                    "the scene has {} camera(s); index {index} is out of range",
                    scene.cameras.len()
                ))
            });
        }
        if !s.contains('=') {
            return scene
                .cameras
                .iter()
                .find(|c| c.name == s)
                .map(|c| c.camera)
                .ok_or_else(|| {
                    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
                    err(format!(
                        "no camera named `{s}` (cameras: {})",
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(", ")
                        }
                    ))
                });
        }
        let base = scene.default_camera();
        let mut cam = base;
        let mut target_given = false;
        let mut clip_given = (false, false);
        for part in s.split(';').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| err(format!("`{part}` is not key=value")))?;
            let key = key.trim().to_ascii_lowercase();
            let num = |v: &str| -> Result<f32, SceneError> {
                let x: f32 = v
                    .trim()
                    .parse()
                    .map_err(|_| err(format!("`{v}` is not a number (in `{part}`)")))?;
                if x.is_finite() {
                    Ok(x)
                } else {
                    Err(err(format!("`{v}` is not finite")))
                }
            };
            let vec3 = |v: &str| -> Result<Vec3, SceneError> {
                let parts: Vec<&str> = v.split(',').collect();
                if parts.len() != 3 {
                    return Err(err(format!("`{key}` needs x,y,z (got `{v}`)")));
                }
                Ok(Vec3::new(num(parts[0])?, num(parts[1])?, num(parts[2])?))
            };
            match key.as_str() {
                "eye" | "pos" | "position" => cam.eye = vec3(value)?,
                "target" | "at" | "look" => {
                    cam.target = vec3(value)?;
                    target_given = true;
                }
                "up" => cam.up = vec3(value)?,
                "fov" | "fovy" | "fov_y" => {
                    let deg = num(value)?;
                    if !(1.0..=179.0).contains(&deg) {
                        return Err(err(format!("fov {deg} is outside 1..179 degrees")));
                    }
                    cam.fov_y = deg.to_radians();
                }
                "near" => {
                    cam.near = num(value)?;
                    clip_given.0 = true;
                }
                "far" => {
                    cam.far = num(value)?;
                    clip_given.1 = true;
                }
                other => {
                    return Err(err(format!(
                        "unknown key `{other}` (use eye, target, up, fov, near, far)"
                    )))
                }
            }
        }
        if !target_given && cam.eye != base.eye {
            cam.target = scene.bounds().center();
        }
        if (cam.target - cam.eye).length_squared() < 1e-12 {
            return Err(err("eye and target are the same point".into()));
        }
        let (near, far) = scene.fit_clip(&cam);
        if !clip_given.0 {
            cam.near = near;
        }
        if !clip_given.1 {
            cam.far = far;
        }
        if !(cam.near > 0.0 && cam.far > cam.near) {
            return Err(err(format!(
                "need 0 < near < far (near {}, far {})",
                cam.near, cam.far
            )));
        }
        Ok(cam)
    }
}

impl fmt::Display for Camera {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "eye={},{},{};target={},{},{};up={},{},{};fov={};near={};far={}",
            self.eye.x,
            self.eye.y,
            self.eye.z,
            self.target.x,
            self.target.y,
            self.target.z,
            self.up.x,
            self.up.y,
            self.up.z,
            self.fov_y.to_degrees(),
            self.near,
            self.far
        )
    }
}

/// Right-handed view matrix looking from `eye` along `dir`.
pub fn look_to_rh(eye: Vec3, dir: Vec3, up: Vec3) -> Mat4 {
    let f = dir.normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-eye.dot(s), -eye.dot(u), eye.dot(f), 1.0),
    )
}

/// Right-handed perspective projection to clip space with depth 0 (near) .. 1 (far).
pub fn perspective_rh(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let f = 1.0 / (fov_y * 0.5).tan();
    let r = far / (near - far);
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, r, -1.0),
        Vec4::new(0.0, 0.0, r * near, 0.0),
    )
}

/// A camera defined by the scene (glTF or built-in).
#[derive(Debug, Clone)]
pub struct NamedCamera {
    pub name: String,
    pub camera: Camera,
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
}

impl Scene {
    /// Loads `builtin:room`, `builtin:bench`, or a `.gltf` / `.glb` file.
    ///
    /// A scene without lights gets [`Scene::default_lights`].
    pub fn load(source: &str) -> Result<Scene, SceneError> {
        let mut scene = if let Some(name) = source.strip_prefix("builtin:") {
            super::builtin::builtin(name)?
        } else {
            super::gltf_load::load_gltf(std::path::Path::new(source))?
        };
        scene.ensure_lights();
        scene.validate()?;
        Ok(scene)
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

    /// Adds `n` point lights (seed 004): a position uniformly inside the scene bounds,
    /// a radius between 4 % and 10 % of the bounds' diagonal, a saturated random hue
    /// and intensity 1. Deterministic for a seed (own xorshift PRNG).
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
        Ok(())
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
    fn point_radius_round_trips() {
        let l = Light::point(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.2), 3.0, 2.5);
        assert!((l.radius() - 2.5).abs() < 1e-4, "{}", l.radius());
        let [a, b, c] = l.attenuation;
        let f = 3.0 / (a + b * 2.5 + c * 2.5 * 2.5);
        assert!((f - ATTENUATION_THRESHOLD).abs() < 1e-6);
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
