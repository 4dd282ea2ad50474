//! glTF lights and cameras: `KHR_lights_punctual` lights and perspective cameras,
//! placed by their node's world transform and checked; they remember the node,
//! so that animating it moves them.

use crate::scene::model::{Camera, Light, LightKind, NamedCamera};
use glam::{Mat4, Vec3};

/// A perspective camera placed by the node's world transform (at its origin,
/// looking down its −Z with its +Y up), named after the camera or else the node
/// `node_name`; an invalid perspective is an error. An orthographic camera is
/// ignored with a warning (`None`).
pub(super) fn convert_camera(
    file: &str,
    cam: &gltf::Camera,
    world: &Mat4,
    node: usize,
    node_name: &str,
) -> Result<Option<NamedCamera>, String> {
    match cam.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let near = p.znear();
            let far = p.zfar().unwrap_or(near * 1e5);
            let yfov = p.yfov();
            if !(near > 0.0 && far > near && yfov > 0.0 && yfov < 3.1) {
                return Err(format!(
                    "camera {}: invalid perspective (znear {near}, zfar {far}, yfov {yfov})",
                    cam.index()
                ));
            }
            let mut camera = Camera {
                eye: Vec3::ZERO,
                target: Vec3::NEG_Z,
                up: Vec3::Y,
                fov_y: yfov,
                near,
                far,
            };
            camera.place(world);
            Ok(Some(NamedCamera {
                name: cam
                    .name()
                    .map(str::to_string)
                    .unwrap_or_else(|| node_name.to_string()),
                camera,
                node: Some(node),
            }))
        }
        gltf::camera::Projection::Orthographic(_) => {
            log::warn!("{}: orthographic camera {} ignored", file, cam.index());
            Ok(None)
        }
    }
}

/// A `KHR_lights_punctual` light placed by the node's world transform: colour and
/// intensity as given (directional: lux; point, spot: candela), falling off with
/// the inverse square of the distance (attenuation `[0, 0, 1]`; the renderer keeps
/// `d` away from 0) inside the optional `range`, spot cones as given (half-angles).
/// A negative or non-finite intensity or colour, or a range that is not positive,
/// is an error; a light of intensity 0 is kept with a warning.
pub(super) fn convert_light(
    file: &str,
    light: &gltf::khr_lights_punctual::Light,
    world: &Mat4,
    node: usize,
) -> Result<Light, String> {
    let name = light
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("light {}", light.index()));
    let label = format!("light {} ({name})", light.index());
    let color = Vec3::from(light.color());
    let intensity = light.intensity();
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "{label}: colour {color} must be finite and not negative"
        ));
    }
    if !intensity.is_finite() || intensity < 0.0 {
        return Err(format!(
            "{label}: intensity {intensity} must be finite and not negative"
        ));
    }
    if intensity == 0.0 || color.max_element() == 0.0 {
        log::warn!("{file}: {label} has intensity 0 (it lights nothing)");
    }
    let range = match light.range() {
        Some(r) if !(r.is_finite() && r > 0.0) => {
            return Err(format!("{label}: range {r} must be a positive number"))
        }
        r => r,
    };
    let kind = match light.kind() {
        gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
        gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            if !(inner_cone_angle.is_finite() && outer_cone_angle.is_finite()) {
                return Err(format!("{label}: non-finite spot cone angles"));
            }
            let outer = outer_cone_angle.clamp(1e-3, std::f32::consts::FRAC_PI_2);
            let inner = inner_cone_angle.clamp(0.0, outer);
            if inner != inner_cone_angle || outer != outer_cone_angle || inner >= outer {
                log::warn!(
                    "{file}: {label}: spot cone angles (inner {inner_cone_angle}, outer \
                     {outer_cone_angle}) outside 0 <= inner < outer <= pi/2; using inner \
                     {inner}, outer {outer}"
                );
            }
            LightKind::Spot { inner, outer }
        }
    };
    let range = match kind {
        LightKind::Point | LightKind::Spot { .. } => range,
        _ => None,
    };
    let mut out = Light {
        name,
        kind,
        color,
        intensity,
        position: Vec3::ZERO,
        direction: Vec3::NEG_Z,
        attenuation: [0.0, 0.0, 1.0],
        range,
        casts_shadows: true,
        node: Some(node),
    };
    out.place(world);
    Ok(out)
}
