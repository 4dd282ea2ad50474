//! A CPU oracle of the material lighting shaders, written from the definitions and
//! independent of the WGSL code: the BRDFs (`lambert`, `phong`, `blinn_phong`,
//! `cook_torrance`), the glTF 2.0 BRDF in the specification's own first form
//! ([`gltf_spec_brdf`]), `KHR_lights_punctual` light falloff ([`illuminance`]) and
//! an analytic ray-traced sphere ([`render_sphere_oracle`]) with the renderer's
//! camera conventions.
//!
//! Every BRDF function returns `(diffuse_factor, specular)` for one light of
//! illuminance `light` (lux, colour × intensity × attenuation, on a surface facing
//! it) arriving from the unit direction `l` (towards the light), seen from the unit
//! direction `v` (towards the eye) on a surface of unit normal `n`; `ndl =
//! max(n·l, 0)`. The reflected radiance of a surface is
//!
//! ```text
//! diffuse_colour · Σ diffuse_factor + Σ specular + emission
//!     + Σ_ambient (ambient colour · intensity) · occlusion · diffuse_colour
//! ```

use fxgraph::scene::{Camera, Light, LightKind};
use glam::Vec3;
use std::f32::consts::PI;

/// Lambert: diffuse `light · ndl / π`, no specular.
pub fn lambert(n: Vec3, l: Vec3, light: Vec3) -> (Vec3, Vec3) {
    let ndl = n.dot(l).max(0.0);
    (light * ndl / PI, Vec3::ZERO)
}

/// Normalised Phong with exponent `p` and specular reflectance `f0`: diffuse as
/// Lambert, specular `light · ndl · F0 · (p + 2)/(2π) · max(reflect(−l, n)·v, 0)^p`.
pub fn phong(p: f32, f0: Vec3, n: Vec3, v: Vec3, l: Vec3, light: Vec3) -> (Vec3, Vec3) {
    let ndl = n.dot(l).max(0.0);
    if ndl <= 0.0 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let r = reflect(-l, n);
    let s = r.dot(v).max(0.0).powf(p);
    (
        light * ndl / PI,
        light * ndl * f0 * ((p + 2.0) / (2.0 * PI)) * s,
    )
}

/// Normalised Blinn-Phong with exponent `p`: diffuse as Lambert, specular
/// `light · ndl · F0 · (p + 8)/(8π) · max(n·h, 0)^p`, `h = normalize(l + v)`.
pub fn blinn_phong(p: f32, f0: Vec3, n: Vec3, v: Vec3, l: Vec3, light: Vec3) -> (Vec3, Vec3) {
    let ndl = n.dot(l).max(0.0);
    if ndl <= 0.0 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let h = (l + v).normalize_or_zero();
    let s = n.dot(h).max(0.0).powf(p);
    (
        light * ndl / PI,
        light * ndl * f0 * ((p + 8.0) / (8.0 * PI)) * s,
    )
}

/// Smallest `α = roughness²` used by [`cook_torrance`]: at `α = 0` the GGX
/// distribution is a delta (a point light's mirror image has no extent).
pub const MIN_ALPHA: f32 = 1e-3;

/// Cook-Torrance as in the glTF 2.0 specification, Appendix B, section
/// "Implementation": `α = roughness²` (at least [`MIN_ALPHA`]),
/// `F = F0 + (1 − F0)(1 − |v·h|)^5`, `D = α² / (π((n·h)²(α² − 1) + 1)²)`, the
/// height-correlated Smith visibility
/// `V = 0.5 / (ndl·sqrt(ndv²(1 − α²) + α²) + ndv·sqrt(ndl²(1 − α²) + α²))`;
/// specular `light · ndl · F·D·V`, diffuse factor `light · ndl · (1 − F)/π`.
/// `ndv = max(n·v, 0)`.
pub fn cook_torrance(
    f0: Vec3,
    roughness: f32,
    n: Vec3,
    v: Vec3,
    l: Vec3,
    light: Vec3,
) -> (Vec3, Vec3) {
    let ndl = n.dot(l).max(0.0);
    if ndl <= 0.0 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let ndv = n.dot(v).max(0.0);
    let h = (l + v).normalize_or_zero();
    let ndh = n.dot(h).max(0.0);
    let vdh = v.dot(h).abs();
    let a = (roughness * roughness).max(MIN_ALPHA);
    let a2 = a * a;
    let f = f0 + (Vec3::ONE - f0) * (1.0 - vdh).powi(5);
    let dd = ndh * ndh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * dd * dd);
    let vis = 0.5
        / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt() + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt());
    (
        light * ndl * (Vec3::ONE - f) / PI,
        light * ndl * f * d * vis,
    )
}

/// The glTF 2.0 BRDF written straight from the specification's first formulation
/// (Appendix B, "Complete Model"), times `max(n·l, 0)`: the reflected radiance
/// under 1 lux from `l`.
///
/// ```text
/// material = mix(dielectric_brdf, metal_brdf, metallic)
/// metal_brdf = conductor_fresnel(f0 = baseColor, bsdf = specular_brdf(α = roughness²))
/// dielectric_brdf = fresnel_mix(ior = 1.5, base = diffuse_brdf(baseColor),
///                               layer = specular_brdf(α = roughness²))
/// specular_brdf(α) = V·D,  diffuse_brdf(c) = c/π
/// conductor_fresnel(f0, bsdf) = bsdf · (f0 + (1 − f0)(1 − |v·h|)^5)
/// fresnel_mix(ior, base, layer) = mix(base, layer, fr),
///     fr = f0 + (1 − f0)(1 − |v·h|)^5, f0 = ((1 − ior)/(1 + ior))²
/// ```
///
/// It equals [`cook_torrance`] with `c_diff = mix(base, 0, metallic)` and
/// `F0 = mix(0.04, base, metallic)` at metallic 0 and 1; in between the two forms
/// differ in the diffuse term only (see the test `gltf_spec_forms_agree`).
pub fn gltf_spec_brdf(
    base: Vec3,
    metallic: f32,
    roughness: f32,
    n: Vec3,
    v: Vec3,
    l: Vec3,
) -> Vec3 {
    let ndl = n.dot(l).max(0.0);
    if ndl <= 0.0 {
        return Vec3::ZERO;
    }
    let ndv = n.dot(v).max(0.0);
    let h = (l + v).normalize_or_zero();
    let vdh = v.dot(h).abs();
    let ndh = n.dot(h).max(0.0);
    let a = (roughness * roughness).max(MIN_ALPHA);
    let a2 = a * a;
    // V_GGX (height-correlated Smith over 4 |n·l| |n·v|) and D_GGX.
    let vis = 0.5
        / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt() + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt());
    let dd = ndh * ndh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * dd * dd);
    let specular_brdf = vis * d;
    let w = (1.0 - vdh).powi(5);
    let conductor_fresnel = |f0: Vec3, bsdf: f32| bsdf * (f0 + (Vec3::ONE - f0) * w);
    let fresnel_mix = |ior: f32, base: Vec3, layer: f32| {
        let f0 = ((1.0 - ior) / (1.0 + ior)).powi(2);
        let fr = f0 + (1.0 - f0) * w;
        base * (1.0 - fr) + Vec3::splat(layer * fr)
    };
    let metal_brdf = conductor_fresnel(base, specular_brdf);
    let dielectric_brdf = fresnel_mix(1.5, base / PI, specular_brdf);
    (dielectric_brdf * (1.0 - metallic) + metal_brdf * metallic) * ndl
}

/// The reflection of `i` about `n`: `i − 2(n·i)n` (as WGSL's `reflect`).
pub fn reflect(i: Vec3, n: Vec3) -> Vec3 {
    i - 2.0 * n.dot(i) * n
}

/// The lighting model of a material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    Lambert,
    /// Phong with this specular exponent.
    Phong(f32),
    /// Blinn-Phong with this specular exponent.
    BlinnPhong(f32),
    CookTorrance,
}

/// `(diffuse_factor, specular)` of `model` (see the module documentation).
pub fn shade_one(
    model: Model,
    f0: Vec3,
    roughness: f32,
    n: Vec3,
    v: Vec3,
    l: Vec3,
    light: Vec3,
) -> (Vec3, Vec3) {
    match model {
        Model::Lambert => lambert(n, l, light),
        Model::Phong(p) => phong(p, f0, n, v, l, light),
        Model::BlinnPhong(p) => blinn_phong(p, f0, n, v, l, light),
        Model::CookTorrance => cook_torrance(f0, roughness, n, v, l, light),
    }
}

/// What a surface shader hands the lighting: colours, roughness, emission and
/// ambient occlusion (linear).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    pub diffuse: Vec3,
    /// Specular reflectance at normal incidence.
    pub f0: Vec3,
    /// Perceptual roughness (Cook-Torrance).
    pub roughness: f32,
    pub emission: Vec3,
    /// Scales ambient light only.
    pub occlusion: f32,
}

impl Surface {
    /// No emission, no occlusion.
    pub fn new(diffuse: Vec3, f0: Vec3, roughness: f32) -> Surface {
        Surface {
            diffuse,
            f0,
            roughness,
            emission: Vec3::ZERO,
            occlusion: 1.0,
        }
    }

    /// The glTF metallic-roughness surface: `c_diff = mix(base, 0, metallic)`,
    /// `F0 = mix(0.04, base, metallic)`.
    pub fn metallic_roughness(base: Vec3, metallic: f32, roughness: f32) -> Surface {
        Surface::new(
            base * (1.0 - metallic),
            Vec3::splat(0.04).lerp(base, metallic),
            roughness,
        )
    }
}

/// The illuminance a point, spot or directional light gives at `p` on a surface
/// facing it, and the unit direction from `p` towards the light; `None` for
/// ambient lights and where it gives nothing.
///
/// Point and spot lights: `colour · intensity / (a + b·d + c·d²)` with the light's
/// `attenuation = [a, b, c]` (`[0, 0, 1]` for glTF lights: the inverse square law
/// of `KHR_lights_punctual`, `d` kept ≥ `1e-4`), times the range window
/// `clamp(1 − (d/range)⁴, 0, 1)` when the light has a range, times `t²` for spots
/// with `t = clamp((cos θ − cos outer)/(cos inner − cos outer), 0, 1)`. With
/// `cut_off`, also zero beyond [`Light::radius`] (the scene model's
/// [`fxgraph::scene::ATTENUATION_THRESHOLD`] cut-off). Directional lights:
/// `colour · intensity` from `−direction`.
pub fn illuminance(light: &Light, p: Vec3, cut_off: bool) -> Option<(Vec3, Vec3)> {
    let rgb = light.color * light.intensity;
    match light.kind {
        LightKind::Ambient => None,
        LightKind::Directional => Some((-light.direction.normalize(), rgb)),
        LightKind::Point | LightKind::Spot { .. } => {
            let to_light = light.position - p;
            let d = to_light.length().max(1e-4);
            let l = to_light / d;
            if cut_off && d > light.radius() {
                return None;
            }
            let [a, b, c] = light.attenuation;
            let mut f = 1.0 / (a + b * d + c * d * d);
            if let Some(range) = light.range {
                f *= (1.0 - (d / range).powi(4)).clamp(0.0, 1.0);
            }
            if let LightKind::Spot { inner, outer } = light.kind {
                let cos_theta = light.direction.normalize().dot(-l);
                let (ci, co) = (inner.cos(), outer.cos());
                let t = if ci > co {
                    ((cos_theta - co) / (ci - co)).clamp(0.0, 1.0)
                } else if cos_theta >= co {
                    1.0
                } else {
                    0.0
                };
                f *= t * t;
            }
            Some((l, rgb * f))
        }
    }
}

/// Reflected radiance of `surface` at a point of normal `n` and position `p` seen
/// from `v` under `lights` (see the module documentation).
pub fn radiance(
    surface: &Surface,
    model: Model,
    p: Vec3,
    n: Vec3,
    v: Vec3,
    lights: &[Light],
    cut_off: bool,
) -> Vec3 {
    let mut diffuse = Vec3::ZERO;
    let mut specular = Vec3::ZERO;
    let mut ambient = Vec3::ZERO;
    for light in lights {
        if light.kind == LightKind::Ambient {
            ambient += light.color * light.intensity;
            continue;
        }
        if let Some((l, e)) = illuminance(light, p, cut_off) {
            let (d, s) = shade_one(model, surface.f0, surface.roughness, n, v, l, e);
            diffuse += d;
            specular += s;
        }
    }
    surface.diffuse * diffuse
        + specular
        + surface.emission
        + ambient * surface.occlusion * surface.diffuse
}

/// A perspective camera as the renderer uses it (`Camera::view` with
/// `perspective_rh`), plus the image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OracleCamera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Width / height of the view (normally `width / height`).
    pub aspect: f32,
    pub width: u32,
    pub height: u32,
}

impl OracleCamera {
    /// The oracle twin of `camera` for a `width` x `height` image.
    pub fn of(camera: &Camera, width: u32, height: u32) -> OracleCamera {
        OracleCamera {
            eye: camera.eye,
            target: camera.target,
            up: camera.up,
            fov_y: camera.fov_y,
            aspect: width as f32 / height as f32,
            width,
            height,
        }
    }

    /// The world-space ray (origin, unit direction) through the centre of pixel
    /// `(x, y)`: NDC `((x + 0.5)/w · 2 − 1, 1 − (y + 0.5)/h · 2)` (y down in the
    /// image, up in NDC), view space looking down −Z with +Y up, right = f × up.
    pub fn ray(&self, x: u32, y: u32) -> (Vec3, Vec3) {
        let f = (self.target - self.eye).normalize();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        let t = (self.fov_y * 0.5).tan();
        let ndc_x = (x as f32 + 0.5) / self.width as f32 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f32 + 0.5) / self.height as f32 * 2.0;
        let dir = s * (ndc_x * self.aspect * t) + u * (ndc_y * t) + f;
        (self.eye, dir.normalize())
    }
}

/// The camera of the sphere tests (a unit sphere at the origin): on +Z at 3.2,
/// 45° vertical field of view, and its oracle twin for a `px` × `px` image.
pub fn sphere_camera(px: u32) -> (Camera, OracleCamera) {
    let cam = Camera {
        eye: Vec3::new(0.0, 0.0, 3.2),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 45f32.to_radians(),
        near: 0.5,
        far: 10.0,
    };
    let o = OracleCamera::of(&cam, px, px);
    (cam, o)
}

/// The nearest positive hit distance of a ray (unit direction) with a sphere.
pub fn ray_sphere(origin: Vec3, dir: Vec3, centre: Vec3, radius: f32) -> Option<f32> {
    let oc = origin - centre;
    let b = oc.dot(dir);
    let c = oc.length_squared() - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    [-b - sq, -b + sq].into_iter().find(|t| *t > 0.0)
}

/// Ray-traces one sphere: per pixel (row-major, top row first) the radiance of the
/// analytic sphere at the pixel centre (the exact normal, no shadows, the light
/// cut-off of [`illuminance`] applied), `None` where the ray misses.
pub fn render_sphere_oracle(
    camera: &OracleCamera,
    centre: Vec3,
    radius: f32,
    surface: &Surface,
    model: Model,
    lights: &[Light],
) -> Vec<Option<Vec3>> {
    let mut out = Vec::with_capacity((camera.width * camera.height) as usize);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let (o, d) = camera.ray(x, y);
            out.push(ray_sphere(o, d, centre, radius).map(|t| {
                let p = o + d * t;
                let n = (p - centre).normalize();
                radiance(surface, model, p, n, -d, lights, true)
            }));
        }
    }
    out
}

/// `∫ f(l, v) cos θ_l dω` over the hemisphere of `n = +Z` (midpoint rule in θ and
/// φ): the directional albedo of `model` for a viewer at `v`, as
/// (diffuse factor, specular) — a white furnace of radiance 1.
pub fn hemisphere_albedo(
    model: Model,
    f0: Vec3,
    roughness: f32,
    v: Vec3,
    steps: u32,
) -> (Vec3, Vec3) {
    let (nt, np) = (steps, steps * 2);
    let (dt, dp) = (0.5 * PI / nt as f32, 2.0 * PI / np as f32);
    let mut sum = (Vec3::ZERO, Vec3::ZERO);
    for i in 0..nt {
        let theta = (i as f32 + 0.5) * dt;
        let d_omega = theta.sin() * dt * dp;
        for j in 0..np {
            let phi = (j as f32 + 0.5) * dp;
            let l = Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let (d, s) = shade_one(model, f0, roughness, Vec3::Z, v, l, Vec3::splat(d_omega));
            sum.0 += d;
            sum.1 += s;
        }
    }
    sum
}

/// The directions of a `steps` × 2·`steps` grid uniform in GGX's cumulative
/// distribution of the half vector about normal `n` (ξ₁ → cos²θh = (1 − ξ₁) /
/// (1 + (α² − 1) ξ₁), ξ₂ → φ), reflected about `v`: `f(l, w)` for each `l`
/// above the surface, `w = 1 / (N pdf(l))`, `pdf(l) = D cosθh / (4 v·h)`, so
/// that Σ g(l) w estimates ∫ g dω. Where the lobe is a degree wide (roughness
/// 0.1), an angle grid needs thousands of steps to resolve it; this one puts
/// its points where the lobe is.
pub fn for_each_ggx_grid_direction(
    roughness: f32,
    n: Vec3,
    v: Vec3,
    steps: u32,
    mut f: impl FnMut(Vec3, f32),
) {
    let a = (roughness * roughness).max(MIN_ALPHA);
    let a2 = a * a;
    let across = v - n.dot(v) * n;
    let b1 = if across.length() > 1e-5 {
        across.normalize()
    } else {
        n.any_orthonormal_vector()
    };
    let b2 = n.cross(b1);
    let (nt, np) = (steps, 2 * steps);
    let count = (nt * np) as f32;
    for i in 0..nt {
        let xi = (i as f32 + 0.5) / nt as f32;
        let cos_h = ((1.0 - xi) / (1.0 + (a2 - 1.0) * xi)).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        for j in 0..np {
            let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
            let h = b1 * (sin_h * phi.cos()) + b2 * (sin_h * phi.sin()) + n * cos_h;
            let vdh = v.dot(h);
            let l = 2.0 * vdh * h - v;
            if vdh <= 0.0 || n.dot(l) <= 0.0 {
                continue;
            }
            let dd = cos_h * cos_h * (a2 - 1.0) + 1.0;
            let pdf = a2 / (PI * dd * dd) * cos_h / (4.0 * vdh);
            f(l, 1.0 / (pdf * count));
        }
    }
}

/// The specular albedo of the Cook-Torrance lobe for `f0` at `v` (n = +Z):
/// ∫ f·cos dω over the hemisphere on [`for_each_ggx_grid_direction`]'s grid.
pub fn specular_albedo_ggx_grid(f0: Vec3, roughness: f32, v: Vec3, steps: u32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for_each_ggx_grid_direction(roughness, Vec3::Z, v, steps, |l, w| {
        let (_, s) = cook_torrance(f0, roughness, Vec3::Z, v, l, Vec3::ONE);
        sum += s * w;
    });
    sum
}
