//! Lights: the [`Light`] model (ambient, directional, point, spot), its
//! constructors and the attenuation cut-off that bounds point and spot lights.
//! (Culling and classifying them for one frame is `lights.rs`.)

use glam::{Mat4, Vec3};

/// Attenuation threshold ε: a point or spot light's volume ends where
/// `intensity · max(colour) · f(d)` with `f(d) = 1 / (a + b·d + c·d²)` (Tang et al.,
/// eq. 2) falls to `ε = 1/256` (one 8-bit step at white). Shading uses the same
/// cut-off, so every technique lights exactly the same points.
pub const ATTENUATION_THRESHOLD: f32 = 1.0 / 256.0;

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
    /// Whether the light may get a shadow map (true for scene lights; the
    /// built-in room's small coloured lights and `--lights N` random lights
    /// have none).
    pub casts_shadows: bool,
    /// The node that places it (glTF `KHR_lights_punctual` on a node): it moves
    /// with the node ([`Light::place`]). `None`: placed by its own fields.
    pub node: Option<usize>,
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
            casts_shadows: true,
            node: None,
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
            casts_shadows: true,
            node: None,
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

    /// Places the light by its node's world matrix: at the node's origin,
    /// shining down the node's −Z (`KHR_lights_punctual`).
    pub fn place(&mut self, world: &Mat4) {
        self.position = world.transform_point3(Vec3::ZERO);
        self.direction = world
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z);
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
}
