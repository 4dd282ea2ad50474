//! Fog in the lighting template (the materials-and-effects paper: the template "supports several light
//! sources, shadows and fog"): distance and height fog applied per fragment in
//! forward shading and the light pre-pass final pass, and per pixel in deferred
//! composition, with the parameters and maths of the `fog` effect
//! (effects/fog.fx, shaders/effects/fog/fog.wgsl) so that a scene can be fogged without a
//! post pass. Transparent surfaces are fogged before they are blended.
//!
//! Differences from the effect, both because the renderer knows more: the
//! camera height and the world's up direction come from the camera (the effect
//! takes them as parameters), and the background (no geometry) gets the fog of
//! the view-axis distance `far` without the height term, one colour for the
//! whole sky in every technique (the effect fogs it per pixel).

use crate::scene::Camera;
use glam::{Mat4, Vec3};
use std::fmt;

/// The transmittance curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FogMode {
    Linear,
    #[default]
    Exponential,
    ExponentialSquared,
}

/// What distance the fog grows with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FogDistance {
    /// The view-axis distance (depth).
    #[default]
    Depth,
    /// The Euclidean distance from the camera.
    Radial,
}

/// Fog parameters (names, defaults and ranges as the `fog` effect's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fog {
    pub mode: FogMode,
    pub distance: FogDistance,
    /// Linear colour.
    pub color: Vec3,
    /// Exponential modes: extinction per world unit.
    pub density: f32,
    /// Linear mode: where the fog starts and where it is full.
    pub start: f32,
    pub end: f32,
    /// Density falls by a factor e per 1 / height_falloff units of height (0: none).
    pub height_falloff: f32,
    /// World height where the density is `density`.
    pub fog_height: f32,
}

impl Default for Fog {
    fn default() -> Self {
        Fog {
            mode: FogMode::Exponential,
            distance: FogDistance::Depth,
            color: Vec3::new(0.5, 0.6, 0.7),
            density: 0.05,
            start: 0.0,
            end: 100.0,
            height_falloff: 0.0,
            fog_height: 0.0,
        }
    }
}

/// A `--fog` setting that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("fog {key}: {message}")]
pub struct FogError {
    pub key: String,
    pub message: String,
}

fn number(key: &str, v: &str, lo: f32, hi: f32) -> Result<f32, FogError> {
    let err = |message: String| FogError {
        key: key.into(),
        message,
    };
    let x: f32 = v
        .trim()
        .parse()
        .map_err(|_| err(format!("`{v}` is not a number")))?;
    if !x.is_finite() || x < lo || x > hi {
        return Err(err(format!("{x} is outside {lo}..{hi}")));
    }
    Ok(x)
}

impl Fog {
    /// The parameter names, as the `fog` effect's.
    pub const KEYS: [&'static str; 8] = [
        "mode",
        "distance",
        "color",
        "density",
        "start",
        "end",
        "height_falloff",
        "fog_height",
    ];

    /// Applies `KEY=VALUE` settings (`on` alone keeps the defaults); every
    /// problem of the list is returned.
    pub fn parse(settings: &[String]) -> Result<Fog, Vec<FogError>> {
        let mut fog = Fog::default();
        let mut errors = Vec::new();
        for s in settings {
            if s.trim() == "on" {
                continue;
            }
            let Some((key, value)) = s.split_once('=') else {
                errors.push(FogError {
                    key: s.clone(),
                    message: format!(
                        "expected KEY=VALUE or `on`; keys: {}",
                        Self::KEYS.join(", ")
                    ),
                });
                continue;
            };
            if let Err(e) = fog.set(key.trim(), value.trim()) {
                errors.push(e);
            }
        }
        if fog.mode == FogMode::Linear && fog.end <= fog.start {
            errors.push(FogError {
                key: "end".into(),
                message: format!("must be greater than start ({})", fog.start),
            });
        }
        if errors.is_empty() {
            Ok(fog)
        } else {
            Err(errors)
        }
    }

    fn set(&mut self, key: &str, v: &str) -> Result<(), FogError> {
        let err = |message: String| FogError {
            key: key.into(),
            message,
        };
        match key {
            "mode" => {
                self.mode = match v {
                    "linear" => FogMode::Linear,
                    "exponential" => FogMode::Exponential,
                    "exponential_squared" => FogMode::ExponentialSquared,
                    _ => {
                        return Err(err(format!(
                            "`{v}`: expected linear, exponential or exponential_squared"
                        )))
                    }
                }
            }
            "distance" => {
                self.distance = match v {
                    "depth" => FogDistance::Depth,
                    "radial" => FogDistance::Radial,
                    _ => return Err(err(format!("`{v}`: expected depth or radial"))),
                }
            }
            "color" => {
                let c: Vec<&str> = v.split([',', ' ']).filter(|s| !s.is_empty()).collect();
                let c = match c.as_slice() {
                    [x] => [*x; 3],
                    [r, g, b] => [*r, *g, *b],
                    _ => return Err(err(format!("`{v}`: expected V or R,G,B"))),
                };
                let mut rgb = [0.0; 3];
                for (o, x) in rgb.iter_mut().zip(c) {
                    *o = number(key, x, 0.0, 65504.0)?;
                }
                self.color = Vec3::from(rgb);
            }
            "density" => self.density = number(key, v, 0.0, 1e6)?,
            "start" => self.start = number(key, v, 0.0, 1e9)?,
            "end" => self.end = number(key, v, 0.0, 1e9)?,
            "height_falloff" => self.height_falloff = number(key, v, 0.0, 1e6)?,
            "fog_height" => self.fog_height = number(key, v, -1e9, 1e9)?,
            _ => {
                return Err(err(format!(
                    "unknown fog parameter; expected one of {}",
                    Self::KEYS.join(", ")
                )))
            }
        }
        Ok(())
    }

    /// Transmittance at optical distance `d`.
    pub fn transmittance(&self, d: f32) -> f32 {
        match self.mode {
            FogMode::Linear => {
                ((self.end - d) / (self.end - self.start).max(1e-20)).clamp(0.0, 1.0)
            }
            FogMode::Exponential => (-self.density * d).exp(),
            FogMode::ExponentialSquared => {
                let x = self.density * d;
                (-x * x).exp()
            }
        }
    }

    /// The background colour seen through the fog (view-axis distance `far`, no
    /// height term).
    pub fn background(&self, background: Vec3, far: f32) -> Vec3 {
        self.color.lerp(background, self.transmittance(far))
    }

    /// The shaders' `FxFog` for `camera` with view matrix `view`.
    pub(crate) fn gpu(fog: Option<&Fog>, camera: &Camera, view: &Mat4) -> GpuFog {
        let Some(f) = fog else {
            return GpuFog::default();
        };
        let up = view.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
        GpuFog {
            color: f.color.into(),
            density: f.density,
            up: up.into(),
            start: f.start,
            end: f.end,
            height_falloff: f.height_falloff,
            fog_height: f.fog_height,
            camera_height: camera.eye.y,
            mode: match f.mode {
                FogMode::Linear => 1,
                FogMode::Exponential => 2,
                FogMode::ExponentialSquared => 3,
            },
            distance: match f.distance {
                FogDistance::Depth => 0,
                FogDistance::Radial => 1,
            },
            _pad: [0; 2],
        }
    }
}

impl fmt::Display for Fog {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:?} fog ({:?} distance), colour {}, density {}, start {}, end {}, height falloff {}, fog height {}",
            self.mode,
            self.distance,
            self.color,
            self.density,
            self.start,
            self.end,
            self.height_falloff,
            self.fog_height
        )
    }
}

/// `FxFog` (mode 0: no fog).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuFog {
    pub color: [f32; 3],
    pub density: f32,
    pub up: [f32; 3],
    pub start: f32,
    pub end: f32,
    pub height_falloff: f32,
    pub fog_height: f32,
    pub camera_height: f32,
    pub mode: u32,
    pub distance: u32,
    pub _pad: [u32; 2],
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse_with_every_problem_reported() {
        let fog = Fog::parse(&["density=0.2".into(), "color=1,0.5,0".into()]).unwrap();
        assert_eq!(fog.density, 0.2);
        assert_eq!(fog.color, Vec3::new(1.0, 0.5, 0.0));
        assert_eq!(Fog::parse(&["on".into()]).unwrap(), Fog::default());
        let errors = Fog::parse(&[
            "density=-1".into(),
            "colour=1".into(),
            "mode=thick".into(),
            "oops".into(),
        ])
        .unwrap_err();
        assert_eq!(errors.len(), 4, "{errors:?}");
        let linear = Fog::parse(&["mode=linear".into(), "start=5".into(), "end=5".into()]);
        assert!(linear.is_err());
    }

    #[test]
    fn transmittance_curves() {
        let mut fog = Fog::default();
        assert_eq!(fog.transmittance(0.0), 1.0);
        assert!((fog.transmittance(20.0) - (-1.0f32).exp()).abs() < 1e-6);
        fog.mode = FogMode::Linear;
        fog.start = 10.0;
        fog.end = 20.0;
        assert_eq!(fog.transmittance(5.0), 1.0);
        assert!((fog.transmittance(15.0) - 0.5).abs() < 1e-6);
        assert_eq!(fog.transmittance(25.0), 0.0);
        assert_eq!(std::mem::size_of::<GpuFog>(), 64);
    }
}
