//! Cameras: the perspective [`Camera`], its view and projection matrices, framing
//! a scene, `--camera` spec parsing, and the scene's named cameras.

use super::model::{Aabb, Scene, SceneError};
use glam::{Mat4, Vec3, Vec4};
use std::fmt;

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

    /// Places the camera by its node's world matrix (glTF 2.0 §3.10: at the
    /// node's origin, looking down its −Z, its +Y up), keeping the projection.
    pub fn place(&mut self, world: &Mat4) {
        self.eye = world.transform_point3(Vec3::ZERO);
        let forward = world
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z);
        self.target = self.eye + forward;
        self.up = world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
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
            return camera_named(scene, s).map_err(err);
        }
        let base = scene.default_camera();
        let (mut cam, given) = parse_settings(s, base).map_err(err)?;
        fit_to_scene(&mut cam, base, scene, given).map_err(err)?;
        Ok(cam)
    }
}

/// The scene camera named `name`.
fn camera_named(scene: &Scene, name: &str) -> Result<Camera, String> {
    scene
        .cameras
        .iter()
        .find(|c| c.name == name)
        .map(|c| c.camera)
        .ok_or_else(|| {
            let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
            format!(
                "no camera named `{name}` (cameras: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        })
}

/// Which of the settings that otherwise come from the scene were given.
#[derive(Default, Clone, Copy)]
struct Given {
    target: bool,
    near: bool,
    far: bool,
}

/// `base` with the `key=value` settings of `spec` (separated by `;`) applied.
fn parse_settings(spec: &str, base: Camera) -> Result<(Camera, Given), String> {
    let mut cam = base;
    let mut given = Given::default();
    for part in spec.split(';').map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = part
            .split_once('=')
            .ok_or_else(|| format!("`{part}` is not key=value"))?;
        let key = key.trim().to_ascii_lowercase();
        apply_setting(&mut cam, &mut given, (&key, value), part)?;
    }
    Ok((cam, given))
}

/// Sets `key` (lower case) of `cam` to `value`, from the setting `part`.
fn apply_setting(
    cam: &mut Camera,
    given: &mut Given,
    (key, value): (&str, &str),
    part: &str,
) -> Result<(), String> {
    let num = |v: &str| -> Result<f32, String> {
        let x: f32 = v
            .trim()
            .parse()
            .map_err(|_| format!("`{v}` is not a number (in `{part}`)"))?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!("`{v}` is not finite"))
        }
    };
    let vec3 = |v: &str| -> Result<Vec3, String> {
        let parts: Vec<&str> = v.split(',').collect();
        if parts.len() != 3 {
            return Err(format!("`{key}` needs x,y,z (got `{v}`)"));
        }
        Ok(Vec3::new(num(parts[0])?, num(parts[1])?, num(parts[2])?))
    };
    match key {
        "eye" | "pos" | "position" => cam.eye = vec3(value)?,
        "target" | "at" | "look" => {
            cam.target = vec3(value)?;
            given.target = true;
        }
        "up" => cam.up = vec3(value)?,
        "fov" | "fovy" | "fov_y" => {
            let deg = num(value)?;
            if !(1.0..=179.0).contains(&deg) {
                return Err(format!("fov {deg} is outside 1..179 degrees"));
            }
            cam.fov_y = deg.to_radians();
        }
        "near" => {
            cam.near = num(value)?;
            given.near = true;
        }
        "far" => {
            cam.far = num(value)?;
            given.far = true;
        }
        other => {
            return Err(format!(
                "unknown key `{other}` (use eye, target, up, fov, near, far)"
            ))
        }
    }
    Ok(())
}

/// What was not given comes from the scene: the target is its centre when
/// only the eye moved, near and far are fitted to its bounds. The result must
/// look somewhere, with 0 < near < far.
fn fit_to_scene(cam: &mut Camera, base: Camera, scene: &Scene, given: Given) -> Result<(), String> {
    if !given.target && cam.eye != base.eye {
        cam.target = scene.bounds().center();
    }
    if (cam.target - cam.eye).length_squared() < 1e-12 {
        return Err("eye and target are the same point".into());
    }
    let (near, far) = scene.fit_clip(cam);
    if !given.near {
        cam.near = near;
    }
    if !given.far {
        cam.far = far;
    }
    if !(cam.near > 0.0 && cam.far > cam.near) {
        return Err(format!(
            "need 0 < near < far (near {}, far {})",
            cam.near, cam.far
        ));
    }
    Ok(())
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
#[derive(Debug, Clone, PartialEq)]
pub struct NamedCamera {
    pub name: String,
    pub camera: Camera,
    /// The node that places it (glTF): it moves with the node
    /// ([`Camera::place`]). `None` for built-in cameras.
    pub node: Option<usize>,
}
