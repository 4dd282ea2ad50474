//! Cameras over time (`--camera` for rendered sequences): a fixed camera, a
//! scene camera (which moves with its glTF node when the node is animated), or
//! an orbit around the scene's bounds for models without a camera. A scene camera
//! named like a keyword (`orbit`) is chosen with `--camera name:orbit`.
//!
//! `--camera orbit[:key=value,...]` keys (all optional):
//! - `period=SECONDS` (8): one full turn about +Y per period, counter-clockwise
//!   seen from above (from +Z towards +X);
//! - `elevation=DEGREES` (20): the camera's height angle above the horizontal
//!   plane through the bounds' centre (−89..89);
//! - `start=DEGREES` (0): the azimuth at time 0, 0 = on the +Z side (where the
//!   default camera stands), 90 = on the +X side;
//! - `distance=D`: from the bounds' centre (default: the framing distance of the
//!   default camera, so the whole scene stays in view at every angle);
//! - `fov=DEGREES` (60): vertical field of view.

use super::animation::Pose;
use super::camera::Camera;
use super::model::{Scene, SceneError};
use glam::Vec3;

/// An orbit around a point (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    pub center: Vec3,
    pub distance: f32,
    /// Radians above the horizontal.
    pub elevation: f32,
    /// Azimuth at time 0, radians (0: +Z side, π/2: +X side).
    pub start: f32,
    /// Seconds per turn (positive).
    pub period: f64,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
}

impl Orbit {
    /// The camera at time `t` seconds.
    pub fn at(&self, t: f64) -> Camera {
        // the angle in f64 (long sequences), reduced before the f32 trigonometry
        let turns = (t / self.period).rem_euclid(1.0);
        let azimuth = self.start + (turns * std::f64::consts::TAU) as f32;
        let (ce, se) = (self.elevation.cos(), self.elevation.sin());
        let dir = Vec3::new(azimuth.sin() * ce, se, azimuth.cos() * ce);
        Camera {
            eye: self.center + dir * self.distance,
            target: self.center,
            up: Vec3::Y,
            fov_y: self.fov_y,
            near: self.near,
            far: self.far,
        }
    }
}

/// Where the camera is at each time of a sequence.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraPath {
    /// The same camera at every time.
    Fixed(Camera),
    /// The scene camera with this index (`Scene::cameras`): it follows its node
    /// when the node is animated.
    SceneCamera(usize),
    Orbit(Orbit),
}

impl CameraPath {
    /// Parses `--camera` for a sequence: `orbit[:...]`, a scene camera's index
    /// or name (which may move), or anything [`Camera::parse_spec`] takes (fixed);
    /// `None`: the scene's first camera, else a fixed framing of its bounds.
    ///
    /// `name:NAME` is the scene camera named NAME whatever the name (`name:orbit`,
    /// `name:2`). A scene camera named like a keyword (`orbit`, `orbit:...`, or
    /// the index of another camera) is not what `--camera NAME` chooses
    /// ([`shadowed_camera`] says so, for a warning).
    pub fn parse(spec: Option<&str>, scene: &Scene) -> Result<CameraPath, SceneError> {
        let Some(spec) = spec.map(str::trim) else {
            return Ok(if scene.cameras.is_empty() {
                CameraPath::Fixed(scene.default_camera())
            } else {
                CameraPath::SceneCamera(0)
            });
        };
        if let Some(name) = spec.strip_prefix(NAME_PREFIX) {
            return by_name(spec, name, scene);
        }
        if spec == "orbit" || spec.starts_with("orbit:") {
            return parse_orbit(spec, scene).map(CameraPath::Orbit);
        }
        if let Ok(i) = spec.parse::<usize>() {
            if i < scene.cameras.len() {
                return Ok(CameraPath::SceneCamera(i));
            }
        }
        if let Some(i) = scene.cameras.iter().position(|c| c.name == spec) {
            return Ok(CameraPath::SceneCamera(i));
        }
        Camera::parse_spec(spec, scene).map(CameraPath::Fixed)
    }

    /// The camera at time `t`: a scene camera where `pose` (the scene at `t`)
    /// puts it, or at its rest pose without one.
    pub fn at(&self, scene: &Scene, pose: Option<&Pose>, t: f64) -> Camera {
        match self {
            CameraPath::Fixed(c) => *c,
            CameraPath::SceneCamera(i) => {
                pose.and_then(|p| p.cameras.get(*i))
                    .unwrap_or(&scene.cameras[*i])
                    .camera
            }
            CameraPath::Orbit(o) => o.at(t),
        }
    }

    /// Whether the camera cuts between times `t0` and `t1` (the previous and the
    /// current frame): a scene camera whose node jumps ([`Scene::jumps`]: a
    /// STEP key, or a looping clock that wraps onto another value). Fixed and
    /// orbiting cameras never cut.
    pub fn cuts(&self, scene: &Scene, playback: &crate::scene::Playback, t0: f64, t1: f64) -> bool {
        match self {
            CameraPath::SceneCamera(i) => scene
                .cameras
                .get(*i)
                .and_then(|c| c.node)
                .is_some_and(|n| scene.jumps(playback, n, t0, t1)),
            CameraPath::Fixed(_) | CameraPath::Orbit(_) => false,
        }
    }
}

/// `--camera name:NAME`: a scene camera by its name alone.
pub const NAME_PREFIX: &str = "name:";

/// The scene camera named `name` (`spec`: the whole `name:NAME`, for the error).
fn by_name(spec: &str, name: &str, scene: &Scene) -> Result<CameraPath, SceneError> {
    scene
        .cameras
        .iter()
        .position(|c| c.name == name)
        .map(CameraPath::SceneCamera)
        .ok_or_else(|| {
            let names: Vec<String> = scene
                .cameras
                .iter()
                .map(|c| format!("`{}`", c.name))
                .collect();
            SceneError::Camera {
                spec: spec.to_string(),
                message: format!(
                    "no scene camera named `{name}` (cameras: {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            }
        })
}

/// A warning when `spec` is also the name of a scene camera that `--camera spec`
/// does not choose: the keyword `orbit` (or `orbit:...`), or the index of another
/// camera. `None` when `spec` names nothing else or means that camera anyway.
pub fn shadowed_camera(spec: &str, scene: &Scene) -> Option<String> {
    let spec = spec.trim();
    let named = scene.cameras.iter().position(|c| c.name == spec)?;
    let meaning = if spec == "orbit" || spec.starts_with("orbit:") {
        "the built-in turntable around the scene (orbit)".to_string()
    } else {
        match spec.parse::<usize>() {
            Ok(i) if i != named && i < scene.cameras.len() => {
                format!("scene camera {i} (by index)")
            }
            _ => return None,
        }
    };
    Some(format!(
        "--camera {spec} is {meaning}, not the scene's camera {named} named `{spec}`: choose that one with --camera {NAME_PREFIX}{spec}"
    ))
}

fn parse_orbit(spec: &str, scene: &Scene) -> Result<Orbit, SceneError> {
    let err = |message: String| SceneError::Camera {
        spec: spec.to_string(),
        message,
    };
    let framing = scene.default_camera();
    let bounds = scene.bounds();
    let center = if bounds.is_empty() {
        framing.target
    } else {
        bounds.center()
    };
    let mut orbit = Orbit {
        center,
        distance: (framing.eye - framing.target).length(),
        elevation: 20f32.to_radians(),
        start: 0.0,
        period: 8.0,
        fov_y: framing.fov_y,
        near: framing.near,
        far: framing.far,
    };
    let keys = spec.strip_prefix("orbit").unwrap_or("");
    let keys = keys.strip_prefix(':').unwrap_or(keys);
    let mut distance_given = false;
    for part in keys
        .split([',', ';'])
        .map(str::trim)
        .filter(|p| !p.is_empty())
    {
        let (key, value) = part
            .split_once('=')
            .ok_or_else(|| err(format!("`{part}` is not key=value")))?;
        let x: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .ok_or_else(|| err(format!("`{value}` is not a finite number (in `{part}`)")))?;
        match key.trim() {
            "period" if x > 0.0 => orbit.period = x,
            "period" => return Err(err(format!("period {x}: must be above 0 seconds"))),
            "elevation" if x.abs() < 89.5 => orbit.elevation = (x as f32).to_radians(),
            "elevation" => return Err(err(format!("elevation {x}: must be within ±89 degrees"))),
            "start" => orbit.start = (x as f32).to_radians(),
            "distance" if x > 0.0 => {
                orbit.distance = x as f32;
                distance_given = true;
            }
            "distance" => return Err(err(format!("distance {x}: must be above 0"))),
            "fov" if (1.0..=179.0).contains(&x) => orbit.fov_y = (x as f32).to_radians(),
            "fov" => return Err(err(format!("fov {x}: must be within 1..179 degrees"))),
            other => {
                return Err(err(format!(
                    "unknown orbit key `{other}` (use period, elevation, start, distance, fov)"
                )))
            }
        }
    }
    // clip planes for the orbit's distance, whatever the angle
    let radius = if bounds.is_empty() {
        1.0
    } else {
        (bounds.diagonal() * 0.5).max(1e-3)
    };
    if distance_given || orbit.distance <= radius {
        orbit.near = ((orbit.distance - radius) * 0.5).max(radius * 1e-3);
        orbit.far = orbit.distance + radius * 2.0;
    }
    Ok(orbit)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        Scene::load("builtin:room").unwrap()
    }

    #[test]
    fn an_orbit_turns_once_per_period_counter_clockwise_from_above() {
        let s = scene();
        let CameraPath::Orbit(o) =
            CameraPath::parse(Some("orbit:period=4,elevation=0"), &s).unwrap()
        else {
            panic!("an orbit");
        };
        let c0 = o.at(0.0);
        let c1 = o.at(1.0);
        let c4 = o.at(4.0);
        // t = 0 on the +Z side, a quarter turn later on the +X side
        assert!((c0.eye - o.center).normalize().abs_diff_eq(Vec3::Z, 1e-5));
        assert!((c1.eye - o.center).normalize().abs_diff_eq(Vec3::X, 1e-5));
        assert!(c4.eye.abs_diff_eq(c0.eye, 1e-3));
        assert!(((c0.eye - o.center).length() - o.distance).abs() < 1e-4);
        assert_eq!(c0.target, o.center);
    }

    #[test]
    fn orbit_keys_are_checked() {
        let s = scene();
        for (spec, word) in [
            ("orbit:period=0", "period"),
            ("orbit:elevation=95", "elevation"),
            ("orbit:speed=3", "unknown orbit key"),
            ("orbit:period=x", "not a finite number"),
        ] {
            let e = CameraPath::parse(Some(spec), &s).unwrap_err().to_string();
            assert!(e.contains(word), "{spec}: {e}");
        }
    }

    #[test]
    fn a_camera_named_like_a_keyword_is_chosen_with_name_and_warned_about() {
        let mut s = scene();
        let mut second = s.cameras[0].clone();
        second.camera.eye.x += 1.0;
        s.cameras.truncate(1);
        s.cameras.push(second);
        s.cameras[1].name = "orbit".into();
        s.cameras[0].name = "1".into();
        // the keyword and the index keep their meaning, with a warning each
        assert!(matches!(
            CameraPath::parse(Some("orbit"), &s).unwrap(),
            CameraPath::Orbit(_)
        ));
        let w = shadowed_camera("orbit", &s).expect("a warning");
        assert!(
            w.contains("turntable") && w.contains("camera 1 named `orbit`"),
            "{w}"
        );
        assert!(w.contains("--camera name:orbit"), "{w}");
        assert_eq!(
            CameraPath::parse(Some("1"), &s).unwrap(),
            CameraPath::SceneCamera(1)
        );
        assert!(shadowed_camera("1", &s)
            .unwrap()
            .contains("scene camera 1 (by index)"));
        // name: takes the name alone
        assert_eq!(
            CameraPath::parse(Some("name:orbit"), &s).unwrap(),
            CameraPath::SceneCamera(1)
        );
        assert_eq!(
            CameraPath::parse(Some("name:1"), &s).unwrap(),
            CameraPath::SceneCamera(0)
        );
        let e = CameraPath::parse(Some("name:nope"), &s)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no scene camera named `nope`") && e.contains("`orbit`"),
            "{e}"
        );
        // nothing to warn about: a plain name, a camera's own index, no such name
        let plain = s.cameras[1].name.clone();
        s.cameras[1].name = "front".into();
        assert_eq!(shadowed_camera("orbit", &s), None);
        assert_eq!(shadowed_camera("front", &s), None);
        s.cameras[1].name = plain;
        s.cameras[0].name = "0".into();
        assert_eq!(shadowed_camera("0", &s), None);
    }

    #[test]
    fn other_specs_stay_fixed_cameras() {
        let s = scene();
        let p = CameraPath::parse(Some("eye=0,2,9;target=0,1,0"), &s).unwrap();
        assert!(matches!(p, CameraPath::Fixed(c) if c.eye == Vec3::new(0.0, 2.0, 9.0)));
        // no --camera: the scene's first camera (the room has some), else a
        // framing of the bounds, as for a still
        assert_eq!(
            CameraPath::parse(None, &s).unwrap(),
            CameraPath::SceneCamera(0)
        );
        let mut bare = s.clone();
        bare.cameras.clear();
        assert_eq!(
            CameraPath::parse(None, &bare).unwrap(),
            CameraPath::Fixed(bare.default_camera())
        );
    }
}
