//! `builtin:sky`: an analytic clear daylight sky after A. J. Preetham, P. Shirley
//! and B. Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH 1999), with
//! its sun as a directional light.
//!
//! - Sky radiance: the paper's Perez distribution of luminance Y and chromaticity
//!   x, y (its Appendix A.2 coefficients, linear in the turbidity T), scaled by
//!   the zenith values (zenith luminance in kcd/m², the zenith chromaticity
//!   polynomials), converted xyY → XYZ → linear Rec. 709 / sRGB primaries.
//! - Below the horizon: a grey ground of albedo [`GROUND_ALBEDO`], lit by the sun
//!   and the sky (its radiance is the albedo × their horizontal illuminance / π).
//! - The sun is not in the map: it is a directional light ([`Sky::sun_light`])
//!   so that it casts the renderer's cascaded shadows, of illuminance 128 klux
//!   (the solar illuminance above the atmosphere) × the transmittance of the
//!   paper's Appendix A.2: Rayleigh scattering exp(−0.008735 λ^−4.08 m) and
//!   aerosols exp(−β λ^−1.3 m), β = 0.04608 T − 0.04586, at λ = 0.65, 0.57
//!   and 0.475 µm for red, green and blue, with the relative air mass m of
//!   Kasten and Young (1989); ozone and water vapour are left out.
//! - Units: 100 klux (a high sun) is π, so a white Lambertian surface facing
//!   such a sun has radiance 1, like the default key light; sky radiance in
//!   kcd/m² is scaled alike (× π / 100).

use super::{uv_to_direction, Equirect};
use crate::scene::Light;
use glam::Vec3;
use std::f32::consts::PI;

/// The name of the sky's sun light.
pub const SUN_NAME: &str = "builtin:sky sun";

/// Reflectance of the ground below the horizon.
pub const GROUND_ALBEDO: f32 = 0.25;

/// Scale from klux (or kcd/m²) to the renderer's units: 100 klux → π.
const UNIT: f32 = PI / 100.0;

/// The sky's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sky {
    /// The sun's height above the horizon, degrees (0 .. 90).
    pub elevation: f32,
    /// The sun's direction about +Y, degrees: 0 towards +X, 90 towards +Z (the
    /// map's column u = 0.5 + azimuth / 360).
    pub azimuth: f32,
    /// Atmospheric turbidity T (2: very clear .. 10: hazy).
    pub turbidity: f32,
}

impl Default for Sky {
    fn default() -> Sky {
        Sky {
            elevation: 40.0,
            azimuth: 120.0,
            turbidity: 3.0,
        }
    }
}

/// The Perez function F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ).
fn perez(c: [f32; 5], cos_theta: f32, gamma: f32) -> f32 {
    let [a, b, cc, d, e] = c;
    (1.0 + a * (b / cos_theta.max(1e-3)).exp())
        * (1.0 + cc * (d * gamma).exp() + e * gamma.cos().powi(2))
}

fn xyz_to_rgb(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(
        3.240_454_2 * x - 1.537_138_5 * y - 0.498_531_4 * z,
        -0.969_266 * x + 1.876_010_8 * y + 0.041_556 * z,
        0.055_643_4 * x - 0.204_025_9 * y + 1.057_225_2 * z,
    )
}

impl Sky {
    /// Unit direction towards the sun.
    pub fn sun_direction(&self) -> Vec3 {
        let (e, a) = (self.elevation.to_radians(), self.azimuth.to_radians());
        Vec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
    }

    /// The problems of the settings (`--sun`, `--turbidity`), if any.
    pub fn check(&self) -> Result<(), String> {
        if !(0.0..=90.0).contains(&self.elevation) || !self.azimuth.is_finite() {
            return Err(format!(
                "--sun: elevation {} must be 0..90 degrees and the azimuth finite",
                self.elevation
            ));
        }
        if !(1.7..=10.0).contains(&self.turbidity) {
            return Err(format!(
                "--turbidity {}: the sky model holds for 1.7 .. 10",
                self.turbidity
            ));
        }
        Ok(())
    }

    /// Sky radiance (renderer units, linear sRGB) towards unit direction `d`
    /// above the horizon.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let t = self.turbidity;
        let s = self.sun_direction();
        let theta_s = (PI / 2.0 - self.elevation.to_radians()).clamp(0.0, PI / 2.0);
        let cos_theta = d.y.max(0.0);
        let gamma = d.dot(s).clamp(-1.0, 1.0).acos();
        let cy = [
            0.1787 * t - 1.4630,
            -0.3554 * t + 0.4275,
            -0.0227 * t + 5.3251,
            0.1206 * t - 2.5771,
            -0.0670 * t + 0.3703,
        ];
        let cx = [
            -0.0193 * t - 0.2592,
            -0.0665 * t + 0.0008,
            -0.0004 * t + 0.2125,
            -0.0641 * t - 0.8989,
            -0.0033 * t + 0.0452,
        ];
        let cyy = [
            -0.0167 * t - 0.2608,
            -0.0950 * t + 0.0092,
            -0.0079 * t + 0.2102,
            -0.0441 * t - 1.6537,
            -0.0109 * t + 0.0529,
        ];
        let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
        let y_zenith = ((4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192).max(0.0);
        let (th, th2, th3) = (theta_s, theta_s * theta_s, theta_s * theta_s * theta_s);
        let t2 = t * t;
        let x_zenith = t2 * (0.00166 * th3 - 0.00375 * th2 + 0.00209 * th)
            + t * (-0.02903 * th3 + 0.06377 * th2 - 0.03202 * th + 0.00394)
            + (0.11693 * th3 - 0.21196 * th2 + 0.06052 * th + 0.25886);
        let y_chroma_zenith = t2 * (0.00275 * th3 - 0.00610 * th2 + 0.00317 * th)
            + t * (-0.04214 * th3 + 0.08970 * th2 - 0.04153 * th + 0.00516)
            + (0.15346 * th3 - 0.26756 * th2 + 0.06670 * th + 0.26688);
        let rel = |c: [f32; 5]| perez(c, cos_theta, gamma) / perez(c, 1.0, theta_s);
        let lum = y_zenith * rel(cy);
        let x = x_zenith * rel(cx);
        let y = (y_chroma_zenith * rel(cyy)).max(1e-4);
        let big_x = x * lum / y;
        let big_z = (1.0 - x - y) * lum / y;
        xyz_to_rgb(big_x, lum, big_z).max(Vec3::ZERO) * UNIT
    }

    /// The sun's illuminance (renderer units, linear sRGB) on a surface facing it.
    pub fn sun_illuminance(&self) -> Vec3 {
        let zenith_deg = (90.0 - self.elevation).clamp(0.0, 90.0);
        let cos_z = zenith_deg.to_radians().cos();
        let m = 1.0 / (cos_z + 0.50572 * (96.07995 - zenith_deg).powf(-1.6364));
        let beta = 0.04608 * self.turbidity - 0.04586;
        let tr = |lambda: f32| {
            (-0.008735 * lambda.powf(-4.08) * m).exp() * (-beta * lambda.powf(-1.3) * m).exp()
        };
        Vec3::new(tr(0.65), tr(0.57), tr(0.475)) * 128.0 * UNIT
    }

    /// The sun as a directional light casting shadows.
    pub fn sun_light(&self) -> Light {
        let e = self.sun_illuminance();
        let intensity = e.max_element().max(1e-6);
        Light {
            name: SUN_NAME.into(),
            ..Light::directional(-self.sun_direction(), e / intensity, intensity)
        }
    }

    /// The sky as a `width` × `width / 2` map, the ground below the horizon.
    pub fn map(&self, width: u32) -> Equirect {
        let mut sky = Equirect::from_fn(width, |d| {
            if d.y > 0.0 {
                self.radiance(d)
            } else {
                Vec3::ZERO
            }
        });
        // horizontal illuminance of the sky (the upper half's texels) and the sun
        let mut e_sky = Vec3::ZERO;
        for y in 0..sky.height / 2 {
            let omega = sky.texel_solid_angle(y);
            let v = (y as f32 + 0.5) / sky.height as f32;
            let cos = uv_to_direction(0.5, v).y.max(0.0);
            for x in 0..sky.width {
                e_sky += sky.at(x, y) * omega * cos;
            }
        }
        let e_sun = self.sun_illuminance() * self.elevation.to_radians().sin().max(0.0);
        let ground = (e_sky + e_sun) * GROUND_ALBEDO / PI;
        let w = sky.width;
        for y in sky.height / 2..sky.height {
            for x in 0..w {
                sky.texels[(y * w + x) as usize] = ground;
            }
        }
        sky
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sky_is_blue_overhead_and_brighter_near_the_sun() {
        let s = Sky::default();
        let zenith = s.radiance(Vec3::Y);
        assert!(zenith.z > zenith.x, "zenith {zenith}");
        let near_sun = s.radiance((s.sun_direction() + Vec3::new(0.0, 0.05, 0.0)).normalize());
        let away =
            s.radiance(Vec3::new(-s.sun_direction().x, 0.5, -s.sun_direction().z).normalize());
        assert!(near_sun.y > 2.0 * away.y, "{near_sun} vs {away}");
        // a plausible split: the sky gives a fraction of the sun's light
        let m = s.map(128);
        let mut e = 0.0;
        for y in 0..m.height / 2 {
            let cos = uv_to_direction(0.5, (y as f32 + 0.5) / m.height as f32).y;
            for x in 0..m.width {
                e += m.at(x, y).y * m.texel_solid_angle(y) * cos;
            }
        }
        let sun = s.sun_illuminance().y * s.elevation.to_radians().sin();
        assert!((0.05..1.0).contains(&(e / sun)), "sky / sun {}", e / sun);
    }

    #[test]
    fn a_low_sun_is_redder_and_dimmer() {
        let high = Sky {
            elevation: 70.0,
            ..Sky::default()
        }
        .sun_illuminance();
        let low = Sky {
            elevation: 5.0,
            ..Sky::default()
        }
        .sun_illuminance();
        assert!(low.x / low.z > high.x / high.z);
        assert!(low.y < high.y);
        assert!((2.0..4.0).contains(&high.y), "{high}");
    }
}
