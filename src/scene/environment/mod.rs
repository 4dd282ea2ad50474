//! The light of the world around a scene, as data: an equirectangular
//! environment map of linear radiance (a file, the analytic daylight sky
//! [`Sky`], the procedural [`studio`], or a uniform colour), its intensity and its
//! rotation about +Y. The renderer prefilters it (`crate::render::environment`).
//!
//! # Mapping
//!
//! A world direction `d` (glTF axes: +Y up, right-handed) is the map's texel at
//!
//! ```text
//! u = 0.5 + atan2(d.z, d.x) / (2π)     across the columns, from the left edge
//! v = acos(d.y) / π                    down the rows, from the top (+Y)
//! ```
//!
//! so +X is the middle column, +Z three quarters across, −X the left and right
//! edges, +Y the top row: Blender's and the Khronos glTF Sample Viewer's mapping,
//! so the same file lights a model the same way in fxrun and in them
//! ([`direction_to_uv`], [`uv_to_direction`]). A rotation of θ degrees turns the
//! environment by θ about +Y (right-handed: +X towards −Z for θ = 90°): what was
//! seen along `d` is then seen along `R_y(θ) d`.
//!
//! # Input files
//!
//! [`Environment::load`] reads `.exr` and `.hdr` (linear radiance) and any other
//! image fxrun reads. What it does with unusual files:
//!
//! - the image must be equirectangular, width = 2 × height, at least 8 × 4:
//!   anything else is refused ([`EnvironmentError::Invalid`], exit status 1
//!   in fxrun; a 1×1 file is one);
//! - a missing or unreadable file is an I/O error (exit status 2, as for `-i`
//!   and `--materials`), a corrupt one a decoding error (exit status 1);
//! - 8- and 16-bit files (PNG, JPEG, ...) are accepted as sRGB-encoded display
//!   values, decoded to linear 0..1, with a note: they hold no light brighter
//!   than white, so a sun is clipped (use `--environment-intensity`);
//! - NaN and infinite texels are replaced by 0 with one warning naming the
//!   count; negative ones (lossy EXR compression leaves a few) are set to 0
//!   quietly; values above 65504 (the half floats the GPU stores) are clamped
//!   to it with a warning;
//! - maps wider than [`MAX_WIDTH`] are box-filtered down by halves on the CPU
//!   (the prefiltered cube map is at most 512² per face, which 2048 columns
//!   already over-sample);
//! - alpha is ignored.

mod sky;
mod studio;

pub use sky::Sky;
pub use studio::studio;

use crate::io::{IoError, Pixels};
use glam::Vec3;
use std::f32::consts::PI;
use std::path::PathBuf;

/// Widest map kept; wider ones are halved on the CPU.
pub const MAX_WIDTH: u32 = 2048;
/// Largest texel value kept (the largest finite half float).
pub const MAX_RADIANCE: f32 = 65504.0;

/// Where the environment's radiance comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvironmentSource {
    /// An equirectangular image file (`.exr`, `.hdr`: linear radiance).
    File(PathBuf),
    /// The analytic daylight sky, with its sun.
    Sky(Sky),
    /// The procedural photo studio ([`studio`]).
    Studio,
    /// The same radiance from every direction (a white furnace with 1).
    Uniform(Vec3),
}

/// The environment of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    pub source: EnvironmentSource,
    /// Multiplies the map's radiance (not the sky's sun light).
    pub intensity: f32,
    /// Degrees about +Y (see the module documentation).
    pub rotation: f32,
}

/// What is drawn where no geometry is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Background {
    /// A linear colour (the scene's own by default).
    Color(Vec3),
    /// The environment, blurred to `blur` (0 sharp .. 1: its roughness-1 level).
    Environment { blur: f32 },
    /// Alpha 0 and colour 0 in the HDR image, for compositing.
    Transparent,
}

impl Background {
    /// `--background` values: `environment` or `environment:BLUR` (0..1),
    /// `color:R,G,B` (or `color:V`, linear), `transparent`.
    pub fn parse(spec: &str) -> Result<Background, EnvironmentError> {
        let bad = || {
            EnvironmentError::Spec(format!(
                "--background {spec}: expected environment, environment:BLUR (0 to 1), color:R,G,B or transparent"
            ))
        };
        match spec {
            "environment" => Ok(Background::Environment { blur: 0.0 }),
            "transparent" => Ok(Background::Transparent),
            s => {
                if let Some(b) = s.strip_prefix("environment:") {
                    let blur: f32 = b.trim().parse().map_err(|_| bad())?;
                    if !(0.0..=1.0).contains(&blur) {
                        return Err(bad());
                    }
                    Ok(Background::Environment { blur })
                } else if let Some(c) = s.strip_prefix("color:") {
                    let c = parse_floats(c)
                        .filter(|v| v.to_array().iter().all(|x| x.is_finite() && *x >= 0.0))
                        .ok_or_else(bad)?;
                    Ok(Background::Color(c))
                } else {
                    Err(bad())
                }
            }
        }
    }
}

/// Errors of describing or loading an environment.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EnvironmentError {
    /// The file could not be read or decoded (its own message names it).
    #[error(transparent)]
    Io(#[from] IoError),
    /// The image cannot be an environment map: not 2:1, too small.
    #[error("{path}: {message}")]
    Invalid { path: String, message: String },
    /// A bad `--environment`, `--background`, `--sun` ... value.
    #[error("{0}")]
    Spec(String),
}

impl Environment {
    /// An environment of `source` with intensity 1 and no rotation.
    pub fn new(source: EnvironmentSource) -> Environment {
        Environment {
            source,
            intensity: 1.0,
            rotation: 0.0,
        }
    }

    /// `--environment` values: `none` (→ `None`), `builtin:sky`,
    /// `builtin:studio`, `uniform:V` or `uniform:R,G,B` (linear radiance), or a
    /// file path.
    pub fn parse(spec: &str) -> Result<Option<Environment>, EnvironmentError> {
        let source = match spec {
            "" => return Err(EnvironmentError::Spec("--environment: empty value".into())),
            "none" => return Ok(None),
            "builtin:sky" => EnvironmentSource::Sky(Sky::default()),
            "builtin:studio" => EnvironmentSource::Studio,
            s if s.starts_with("builtin:") => {
                return Err(EnvironmentError::Spec(format!(
                    "unknown built-in environment `{s}` (available: builtin:sky, builtin:studio, uniform:R,G,B, none, or a file)"
                )))
            }
            s if s.starts_with("uniform:") => {
                let v = parse_floats(&s["uniform:".len()..])
                    .filter(|v| v.to_array().iter().all(|x| x.is_finite() && *x >= 0.0))
                    .ok_or_else(|| {
                        EnvironmentError::Spec(format!(
                            "`{s}`: expected uniform:V or uniform:R,G,B with finite values ≥ 0"
                        ))
                    })?;
                EnvironmentSource::Uniform(v)
            }
            path => EnvironmentSource::File(PathBuf::from(path)),
        };
        Ok(Some(Environment::new(source)))
    }

    /// How messages name it.
    pub fn label(&self) -> String {
        match &self.source {
            EnvironmentSource::File(p) => p.display().to_string(),
            EnvironmentSource::Sky(_) => "builtin:sky".into(),
            EnvironmentSource::Studio => "builtin:studio".into(),
            EnvironmentSource::Uniform(c) => format!("uniform:{},{},{}", c.x, c.y, c.z),
        }
    }

    /// The sky's sun, a directional light that casts shadows (`None` for
    /// the other sources).
    pub fn sun(&self) -> Option<crate::scene::Light> {
        match &self.source {
            EnvironmentSource::Sky(s) => Some(s.sun_light()),
            _ => None,
        }
    }

    /// The map: read, checked and cleaned (see the module documentation).
    pub fn load(&self) -> Result<EnvironmentMap, EnvironmentError> {
        match &self.source {
            EnvironmentSource::File(path) => load_file(path),
            EnvironmentSource::Sky(s) => Ok(EnvironmentMap::new(self.label(), s.map(512))),
            EnvironmentSource::Studio => Ok(EnvironmentMap::new(self.label(), studio(512))),
            EnvironmentSource::Uniform(c) => Ok(EnvironmentMap::new(
                self.label(),
                Equirect::from_fn(64, |_| *c),
            )),
        }
    }
}

impl crate::scene::Scene {
    /// Sets the scene's environment. With one, the default lights that
    /// [`Scene::ensure_lights`](crate::scene::Scene::ensure_lights) gives a
    /// scene without lights change: the default ambient light goes (the
    /// environment lights every surface), and a sky's sun replaces the default
    /// key light. A sky's sun is added in every case (a previous sky's sun is
    /// removed first).
    pub fn set_environment(&mut self, env: Option<Environment>) {
        self.lights.retain(|l| l.name != sky::SUN_NAME);
        if let Some(e) = &env {
            let defaults = crate::scene::Scene::default_lights();
            if self.lights == defaults {
                self.lights
                    .retain(|l| l.kind != crate::scene::LightKind::Ambient);
                if e.sun().is_some() {
                    self.lights.clear();
                }
                log::info!(
                    "{}: with the environment {}, the default ambient light{} dropped",
                    self.name,
                    e.label(),
                    if e.sun().is_some() {
                        " and key light (the sky's sun replaces it) are"
                    } else {
                        " is"
                    }
                );
            }
            self.lights.extend(e.sun());
        }
        self.environment = env;
    }
}

fn parse_floats(s: &str) -> Option<Vec3> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>().ok())
        .collect::<Option<_>>()?;
    match v.as_slice() {
        [x] => Some(Vec3::splat(*x)),
        [r, g, b] => Some(Vec3::new(*r, *g, *b)),
        _ => None,
    }
}

/// An equirectangular RGB image of linear radiance, rows top (+Y) first.
#[derive(Debug, Clone, PartialEq)]
pub struct Equirect {
    pub width: u32,
    pub height: u32,
    /// `width × height` texels.
    pub texels: Vec<Vec3>,
}

impl Equirect {
    /// A `width` × `width / 2` map with `f(direction of the texel centre)`.
    pub fn from_fn(width: u32, f: impl Fn(Vec3) -> Vec3) -> Equirect {
        let height = width / 2;
        let mut texels = Vec::with_capacity((width * height) as usize);
        for y in 0..height {
            for x in 0..width {
                let d = uv_to_direction(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                );
                texels.push(f(d));
            }
        }
        Equirect {
            width,
            height,
            texels,
        }
    }

    /// The texel at (x, y).
    pub fn at(&self, x: u32, y: u32) -> Vec3 {
        self.texels[(y * self.width + x) as usize]
    }

    /// Solid angle of a texel of row `y`: (2π / w)(cos θ₀ − cos θ₁).
    pub fn texel_solid_angle(&self, y: u32) -> f32 {
        let t0 = PI * y as f32 / self.height as f32;
        let t1 = PI * (y + 1) as f32 / self.height as f32;
        2.0 * PI / self.width as f32 * (t0.cos() - t1.cos())
    }

    /// Half the width and height, each texel the mean of four.
    pub fn halved(&self) -> Equirect {
        let (w, h) = (self.width / 2, self.height / 2);
        let mut texels = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let s = self.at(2 * x, 2 * y)
                    + self.at(2 * x + 1, 2 * y)
                    + self.at(2 * x, 2 * y + 1)
                    + self.at(2 * x + 1, 2 * y + 1);
                texels.push(s * 0.25);
            }
        }
        Equirect {
            width: w,
            height: h,
            texels,
        }
    }
}

/// (u, v) in [0, 1]² of world direction `d` (unit).
pub fn direction_to_uv(d: Vec3) -> (f32, f32) {
    let u = 0.5 + d.z.atan2(d.x) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    (u, v)
}

/// The unit world direction at (u, v) (inverse of [`direction_to_uv`]).
pub fn uv_to_direction(u: f32, v: f32) -> Vec3 {
    let phi = (u - 0.5) * 2.0 * PI;
    let theta = v * PI;
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

/// A loaded environment map, ready to prefilter.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentMap {
    /// How messages name it (the file, `builtin:sky`, ...).
    pub name: String,
    pub map: Equirect,
    /// A hash of the texels and the size: the prefiltered result is cached by it.
    pub key: u64,
}

impl EnvironmentMap {
    /// Hashes `map` (which must already be clean).
    pub fn new(name: String, map: Equirect) -> EnvironmentMap {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (map.width, map.height).hash(&mut h);
        for t in &map.texels {
            for c in t.to_array() {
                c.to_bits().hash(&mut h);
            }
        }
        EnvironmentMap {
            name,
            map,
            key: h.finish(),
        }
    }
}

/// Replaces NaN, infinite and negative texels by 0 and clamps to
/// [`MAX_RADIANCE`]; returns the counts (non-finite, negative, clamped).
fn sanitize(texels: &mut [Vec3]) -> (usize, usize, usize) {
    let (mut bad, mut negative, mut clamped) = (0, 0, 0);
    for t in texels.iter_mut() {
        for c in [&mut t.x, &mut t.y, &mut t.z] {
            if !c.is_finite() {
                bad += 1;
                *c = 0.0;
            } else if *c < 0.0 {
                negative += 1;
                *c = 0.0;
            } else if *c > MAX_RADIANCE {
                clamped += 1;
                *c = MAX_RADIANCE;
            }
        }
    }
    (bad, negative, clamped)
}

fn load_file(path: &std::path::Path) -> Result<EnvironmentMap, EnvironmentError> {
    let shown = path.display().to_string();
    let img = crate::io::load_image(path, &Default::default())?;
    let (w, h) = (img.width, img.height);
    if w != 2 * h {
        return Err(EnvironmentError::Invalid {
            path: shown,
            message: format!(
                "an environment map is equirectangular (width = 2 × height); this image is {w}x{h}"
            ),
        });
    }
    if h < 4 {
        return Err(EnvironmentError::Invalid {
            path: shown,
            message: format!("an environment map of {w}x{h} is too small (at least 8x4)"),
        });
    }
    if !img.source.float && matches!(img.pixels, Pixels::U8(_)) {
        log::warn!(
            "{shown}: an 8-bit image, read as sRGB-encoded display values (linear 0..1): it holds no light brighter than white (use an .exr or .hdr map, or --environment-intensity)"
        );
    } else if !img.source.float {
        log::warn!(
            "{shown}: a {}-bit integer image, read as sRGB-encoded values (linear 0..1): it holds no light brighter than white",
            img.source.bit_depth
        );
    }
    // linear floats: 8/16-bit decoded from sRGB, float files as stored (NaN kept
    // here, cleaned below)
    let rgba: Vec<f32> = match &img.pixels {
        Pixels::F32(v) => v.clone(),
        p => p.to_f32_linear(false),
    };
    let mut texels: Vec<Vec3> = rgba
        .chunks_exact(4)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let (bad, negative, clamped) = sanitize(&mut texels);
    if bad > 0 {
        log::warn!("{shown}: {bad} NaN or infinite sample(s) replaced by 0");
    }
    if negative > 0 {
        // lossy EXR compression (DWA) leaves small negative values: routine
        log::debug!("{shown}: {negative} negative sample(s) set to 0");
    }
    if clamped > 0 {
        log::warn!(
            "{shown}: {clamped} sample(s) above {MAX_RADIANCE} clamped to it (half-float range)"
        );
    }
    let mut map = Equirect {
        width: w,
        height: h,
        texels,
    };
    while map.width > MAX_WIDTH {
        map = map.halved();
    }
    if map.width != w {
        log::info!(
            "{shown}: {w}x{h} box-filtered to {}x{} for prefiltering",
            map.width,
            map.height
        );
    }
    Ok(EnvironmentMap::new(shown, map))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_puts_the_axes_where_blender_does() {
        let near =
            |(a, b): (f32, f32), (c, d): (f32, f32)| (a - c).abs() < 1e-6 && (b - d).abs() < 1e-6;
        assert!(near(direction_to_uv(Vec3::X), (0.5, 0.5)));
        assert!(near(direction_to_uv(Vec3::Z), (0.75, 0.5)));
        assert!(near(direction_to_uv(Vec3::NEG_Z), (0.25, 0.5)));
        assert!(direction_to_uv(Vec3::Y).1.abs() < 1e-6);
        assert!((direction_to_uv(Vec3::NEG_Y).1 - 1.0).abs() < 1e-6);
        for d in [Vec3::new(0.3, 0.5, -0.8), Vec3::new(-0.9, -0.1, 0.2)] {
            let d = d.normalize();
            let (u, v) = direction_to_uv(d);
            assert!((uv_to_direction(u, v) - d).length() < 1e-5);
        }
    }

    #[test]
    fn texel_solid_angles_sum_to_the_sphere() {
        let m = Equirect::from_fn(64, |_| Vec3::ONE);
        let s: f32 = (0..m.height)
            .map(|y| m.texel_solid_angle(y) * m.width as f32)
            .sum();
        assert!((s - 4.0 * PI).abs() < 1e-4, "{s}");
    }

    #[test]
    fn specs_parse() {
        assert!(Environment::parse("none").unwrap().is_none());
        let e = Environment::parse("uniform:1").unwrap().unwrap();
        assert_eq!(e.source, EnvironmentSource::Uniform(Vec3::ONE));
        assert!(Environment::parse("uniform:1,2").is_err());
        assert!(Environment::parse("uniform:-1").is_err());
        assert!(Environment::parse("builtin:moon").is_err());
        assert!(matches!(
            Environment::parse("a.exr").unwrap().unwrap().source,
            EnvironmentSource::File(_)
        ));
        assert_eq!(
            Background::parse("environment:0.5").unwrap(),
            Background::Environment { blur: 0.5 }
        );
        assert_eq!(
            Background::parse("color:0.1,0.2,0.3").unwrap(),
            Background::Color(Vec3::new(0.1, 0.2, 0.3))
        );
        assert!(Background::parse("environment:2").is_err());
        assert!(Background::parse("sky").is_err());
    }

    #[test]
    fn bad_texels_are_cleaned() {
        let mut t = vec![
            Vec3::new(f32::NAN, 1.0, f32::INFINITY),
            Vec3::new(-2.0, 1e6, 0.5),
        ];
        assert_eq!(sanitize(&mut t), (2, 1, 1));
        assert_eq!(t[0], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(t[1], Vec3::new(0.0, MAX_RADIANCE, 0.5));
    }
}
