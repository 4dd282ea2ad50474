//! The scene camera under the mouse and keys: orbit around the target (left
//! drag), pan (right or middle drag), dolly (wheel), fly (W/A/S/D forward, left,
//! back, right; E/Q up, down; Shift faster). Speeds scale with the scene's size.

use crate::scene::Camera;
use glam::Vec3;

/// Radians of orbit per pixel dragged.
const ORBIT_PER_PIXEL: f32 = 0.005;
/// Distance factor per wheel notch.
const DOLLY_PER_NOTCH: f32 = 0.9;
/// Fly speed in scene radii per second.
const FLY_RADII_PER_SECOND: f32 = 0.6;

/// Keys held for flying.
#[derive(Debug, Default, Clone, Copy)]
pub struct FlyKeys {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    pub fast: bool,
}

impl FlyKeys {
    pub fn any(&self) -> bool {
        self.forward || self.back || self.left || self.right || self.up || self.down
    }

    /// A fly key (W A S D forward, left, back, right; E Q up, down; any case)
    /// pressed or released; false when `letter` is none of them.
    pub fn set_letter(&mut self, letter: &str, pressed: bool) -> bool {
        let slot = match letter.to_lowercase().as_str() {
            "w" => &mut self.forward,
            "s" => &mut self.back,
            "a" => &mut self.left,
            "d" => &mut self.right,
            "e" => &mut self.up,
            "q" => &mut self.down,
            _ => return false,
        };
        *slot = pressed;
        true
    }
}

/// Moves a [`Camera`]; `radius` is half the scene's bounding-box diagonal.
pub struct CameraControl {
    pub radius: f32,
    pub keys: FlyKeys,
}

impl CameraControl {
    pub fn new(radius: f32) -> Self {
        CameraControl {
            radius: radius.max(1e-3),
            keys: FlyKeys::default(),
        }
    }

    /// Orbit the eye around the target by a drag of (`dx`, `dy`) pixels.
    pub fn orbit(&self, cam: &mut Camera, dx: f32, dy: f32) {
        let offset = cam.eye - cam.target;
        let r = offset.length().max(1e-6);
        let mut yaw = offset.x.atan2(offset.z);
        let mut pitch = (offset.y / r).clamp(-1.0, 1.0).asin();
        yaw -= dx * ORBIT_PER_PIXEL;
        let limit = 89f32.to_radians();
        pitch = (pitch + dy * ORBIT_PER_PIXEL).clamp(-limit, limit);
        let dir = Vec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
        cam.eye = cam.target + dir * r;
    }

    /// Move eye and target sideways by a drag of (`dx`, `dy`) pixels of a view
    /// `height` pixels high: the point under the cursor stays under it.
    pub fn pan(&self, cam: &mut Camera, dx: f32, dy: f32, height: f32) {
        let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(cam.up).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let dist = (cam.target - cam.eye).length();
        let per_pixel = 2.0 * dist * (cam.fov_y * 0.5).tan() / height.max(1.0);
        let shift = (-dx * right + dy * up) * per_pixel;
        cam.eye += shift;
        cam.target += shift;
    }

    /// Move the eye towards the target by `notches` wheel notches (negative: away).
    pub fn dolly(&self, cam: &mut Camera, notches: f32) {
        let offset = cam.eye - cam.target;
        let r = (offset.length() * DOLLY_PER_NOTCH.powf(notches)).max(self.radius * 1e-3);
        cam.eye = cam.target + offset.normalize_or(Vec3::Z) * r;
        self.fit_depth(cam);
    }

    /// Fly by the keys held for `dt` seconds; true when the camera moved.
    pub fn fly(&self, cam: &mut Camera, dt: f32) -> bool {
        let k = self.keys;
        if !k.any() {
            return false;
        }
        let forward = (cam.target - cam.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(cam.up).normalize_or(Vec3::X);
        let axis = |a: bool, b: bool| f32::from(u8::from(a)) - f32::from(u8::from(b));
        let dir = forward * axis(k.forward, k.back)
            + right * axis(k.right, k.left)
            + Vec3::Y * axis(k.up, k.down);
        let speed = self.radius * FLY_RADII_PER_SECOND * if k.fast { 4.0 } else { 1.0 };
        let step = dir.normalize_or_zero() * speed * dt.min(0.25);
        cam.eye += step;
        cam.target += step;
        self.fit_depth(cam);
        true
    }

    /// Keep the scene between the near and far planes after the eye moved.
    fn fit_depth(&self, cam: &mut Camera) {
        let dist = (cam.target - cam.eye).length();
        cam.far = cam.far.max(dist + self.radius * 2.0);
        cam.near = cam.near.min((dist * 0.5).max(self.radius * 1e-3));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y: 60f32.to_radians(),
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn orbiting_keeps_the_distance_and_the_target() {
        let c = CameraControl::new(1.0);
        let mut k = cam();
        c.orbit(&mut k, 120.0, -40.0);
        assert!(((k.eye - k.target).length() - 10.0).abs() < 1e-4);
        assert_eq!(k.target, Vec3::ZERO);
        assert!(k.eye.x < 0.0 && k.eye.y < 0.0);
    }

    #[test]
    fn panning_moves_eye_and_target_together_and_dolly_approaches() {
        let c = CameraControl::new(1.0);
        let mut k = cam();
        c.pan(&mut k, 100.0, 0.0, 500.0);
        assert!(k.target.x < 0.0);
        assert!(((k.eye - k.target).length() - 10.0).abs() < 1e-4);
        c.dolly(&mut k, 1.0);
        assert!(((k.eye - k.target).length() - 9.0).abs() < 1e-4);
    }

    #[test]
    fn flying_moves_along_the_view() {
        let mut c = CameraControl::new(10.0);
        c.keys.forward = true;
        let mut k = cam();
        assert!(c.fly(&mut k, 0.1));
        assert!(k.eye.z < 10.0 && k.target.z < 0.0);
    }
}
