//! CPU references of the glTF material layers, written from the extensions'
//! specifications (independent of the WGSL in shaders/render/layers.wgsl):
//!
//! - `KHR_materials_clearcoat`: `coated = mix(material, clearcoat_brdf, w)` with
//!   `w = clearcoat · (0.04 + 0.96 (1 − |v·n_c|)^5)` and `clearcoat_brdf` the glTF
//!   specular BRDF `D·V` (Appendix B, no Fresnel) of `α = clearcoatRoughness²`
//!   about the coat normal `n_c`; emission under the coat.
//! - `KHR_materials_transmission` (thin-walled): the dielectric's base becomes
//!   `mix(diffuse_brdf(baseColor), specular_btdf(α) · baseColor, transmission)`
//!   inside its Fresnel mix; `specular_btdf = V_T · D_T` of the extension's
//!   implementation notes (GGX `D_T`, the separable Smith `V_T`, the
//!   transmission half vector `H_T = normalize(V − 2 (N·L) N + L)`), without
//!   the notes' χ+(H_T·L / N·L) (see [`btdf_thin`]).
//!
//! Plus the scenes the tests render: a sphere or a thin square with a layered
//! standard material, and the environment integrals over an equirectangular
//! map's texels ([`super::ibl::texels`]).
#![allow(dead_code)]

use super::brdf::{cook_torrance, gltf_spec_brdf, illuminance, OracleCamera};
use super::ibl::{irradiance, scattering, Texel, SPHERE_PX};
use fxgraph::gpu::context::GpuContext;
use fxgraph::render::gbuffer::read_rgba_f32;
use fxgraph::render::{Renderer, RendererOptions, Technique};
use fxgraph::scene::{Environment, Instance, Light, Material, Scene, ShaderBinding};
use glam::{Mat4, Vec3};
use std::f32::consts::PI;

/// A layered glTF material (metallic 0 unless said otherwise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layered {
    pub base: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub transmission: f32,
}

impl Layered {
    /// The standard surface's settings of this material, lit by `cook_torrance`.
    pub fn material(&self) -> Material {
        let b = self.base;
        Material::new(
            "layered",
            ShaderBinding::new("standard")
                .with("base_color", &[b.x as f64, b.y as f64, b.z as f64, 1.0])
                .with("metallic", &[self.metallic as f64])
                .with("roughness", &[self.roughness as f64])
                .with("clearcoat", &[self.clearcoat as f64])
                .with("clearcoat_roughness", &[self.clearcoat_roughness as f64])
                .with("transmission", &[self.transmission as f64]),
            ShaderBinding::new("cook_torrance"),
        )
    }

    fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base, self.metallic)
    }
}

/// The coat's weight `clearcoat · Schlick(0.04, |v·n_c|)`.
pub fn coat_weight(clearcoat: f32, nc: Vec3, v: Vec3) -> f32 {
    clearcoat * (0.04 + 0.96 * (1.0 - v.dot(nc).abs()).powi(5))
}

/// The coat lobe `D·V·(n_c·l)` under illuminance `light` (Appendix B's specular
/// term with F = 1: [`cook_torrance`] with F0 = 1).
pub fn coat_lobe(nc: Vec3, v: Vec3, l: Vec3, roughness: f32, light: Vec3) -> Vec3 {
    cook_torrance(Vec3::ONE, roughness, nc, v, l, light).1
}

/// The thin-walled BTDF term for light from `l` behind the surface (n·l < 0):
/// `(1 − F(v·H_T)) · V_T · D_T · |n·l|` (before the base colour and the
/// transmission factor), 0 for light in front.
pub fn btdf_thin(f0: Vec3, roughness: f32, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let ndl = n.dot(l);
    if ndl >= 0.0 {
        return Vec3::ZERO;
    }
    let ndv = n.dot(v).max(1e-4);
    let h = (v - 2.0 * ndl * n + l).normalize_or_zero();
    // (The notes' χ+(H_T·L / N·L) is left out, as the renderer does: with the
    // mirrored direction it would remove about a third of the light a
    // roughness-0.6 wall transmits and three quarters at roughness 1.)
    if h.dot(v) <= 0.0 {
        return Vec3::ZERO;
    }
    let a = (roughness * roughness).max(1e-3);
    let a2 = a * a;
    let ndh = n.dot(h).max(0.0);
    let dd = ndh * ndh * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * dd * dd);
    let (al, av) = (ndl.abs(), ndv);
    let vt = 1.0
        / ((al + (a2 + (1.0 - a2) * al * al).sqrt()) * (av + (a2 + (1.0 - a2) * av * av).sqrt()));
    let f = f0 + (Vec3::ONE - f0) * (1.0 - v.dot(h).abs()).powi(5);
    (Vec3::ONE - f) * (vt * d * al)
}

/// Radiance of `m` at a point `p` of normal `n` (the coat's normal too) seen from
/// `v` under punctual `lights` and an ambient sum (diffuse × ambient, under the
/// coat as the renderer applies it).
pub fn punctual_radiance(m: &Layered, p: Vec3, n: Vec3, v: Vec3, lights: &[Light]) -> Vec3 {
    let f0 = m.f0();
    let c_diff = m.base * (1.0 - m.metallic);
    let (mut diffuse, mut specular, mut transmitted, mut coat) =
        (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    let mut ambient = Vec3::ZERO;
    for light in lights {
        if light.kind == fxgraph::scene::LightKind::Ambient {
            ambient += light.color * light.intensity;
            continue;
        }
        let Some((l, e)) = illuminance(light, p, true) else {
            continue;
        };
        let (d, s) = cook_torrance(f0, m.roughness, n, v, l, e);
        diffuse += d;
        specular += s;
        transmitted += btdf_thin(f0, m.roughness, n, v, l) * e;
        coat += coat_lobe(n, v, l, m.clearcoat_roughness, e);
    }
    let base = c_diff * diffuse.lerp(transmitted, m.transmission) + specular + c_diff * ambient;
    base.lerp(coat, coat_weight(m.clearcoat, n, v))
}

/// Radiance of `m` at a point of normal `n` seen from `v` lit by the environment
/// `t` alone (texels: direction, radiance, solid angle), integrated over every
/// texel: the glTF BRDF with the transmission's base (metallic 0), the
/// thin-walled BTDF over the texels behind, the coat lobe, and the
/// multiple-scattering lobe of Fdez-Agüera that the renderer adds to the base's
/// specular (see `ibl::reference_radiance`).
pub fn environment_radiance(t: &[Texel], m: &Layered, n: Vec3, v: Vec3) -> Vec3 {
    assert!(
        m.metallic == 0.0 || m.transmission == 0.0,
        "transmission of metals"
    );
    let f0 = m.f0();
    let (mut base, mut coat) = (Vec3::ZERO, Vec3::ZERO);
    for (l, le, omega) in t {
        let reflected = if m.metallic == 0.0 {
            // the diffuse part is linear in the base colour, scaled by (1 − T)
            gltf_spec_brdf(m.base * (1.0 - m.transmission), 0.0, m.roughness, n, v, *l)
        } else {
            gltf_spec_brdf(m.base, m.metallic, m.roughness, n, v, *l)
        };
        let through = m.base * m.transmission * btdf_thin(f0, m.roughness, n, v, *l);
        base += (reflected + through) * *le * *omega;
        if m.clearcoat > 0.0 {
            coat += coat_lobe(n, v, *l, m.clearcoat_roughness, *le * *omega);
        }
    }
    let (_, fms_ems) = scattering(f0, m.roughness, n, v);
    base += fms_ems * irradiance(t, n);
    base.lerp(coat, coat_weight(m.clearcoat, n, v))
}

/// A unit sphere at the origin with material `m`.
pub fn sphere(m: &Layered, lights: Vec<Light>, env: Option<Environment>) -> Scene {
    let mut scene = Scene {
        name: format!("layered sphere {m:?}"),
        ..Default::default()
    };
    scene
        .meshes
        .push(fxgraph::scene::builtin::uv_sphere(192, 96));
    scene.materials.push(m.material());
    scene.instances.push(Instance {
        name: "sphere".into(),
        mesh: 0,
        material: 0,
        transform: Mat4::IDENTITY,
        ..Default::default()
    });
    scene.lights = lights;
    scene.environment = env;
    scene
}

/// Side of the square of [`square`].
pub const SQUARE_SIDE: f32 = 2.0;

/// A thin square of side [`SQUARE_SIDE`] in the plane z = 0 facing +Z (the
/// sphere camera's eye), with material `m`.
pub fn square(m: &Layered, lights: Vec<Light>, env: Option<Environment>) -> Scene {
    let mut scene = sphere(m, lights, env);
    scene.name = format!("layered square {m:?}");
    scene.meshes[0] = fxgraph::scene::builtin::grid_plane(8);
    // the XZ plane (normal +Y) turned to face +Z
    scene.instances[0].transform = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(SQUARE_SIDE));
    scene
}

/// The pixels of the square well inside its edges: (x, y, point, normal +Z,
/// direction towards the eye).
pub fn square_pixels(o: &OracleCamera, stride: u32) -> Vec<(u32, u32, Vec3, Vec3, Vec3)> {
    let mut out = Vec::new();
    let half = SQUARE_SIDE * 0.5 - 0.05;
    for y in (0..o.height).step_by(stride as usize) {
        for x in (0..o.width).step_by(stride as usize) {
            let (eye, d) = o.ray(x, y);
            let t = -eye.z / d.z;
            let p = eye + d * t;
            if p.x.abs() < half && p.y.abs() < half {
                out.push((x, y, p, Vec3::Z, -d));
            }
        }
    }
    out
}

/// `scene` rendered by `technique` with the sphere camera
/// ([`super::ibl::sphere_camera`], [`SPHERE_PX`]²), as linear RGBA.
pub fn render(ctx: &GpuContext, scene: &Scene, technique: Technique) -> Vec<[f32; 4]> {
    let mut r = Renderer::new(ctx, scene, &RendererOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", scene.name));
    let (camera, _) = super::ibl::sphere_camera();
    let (out, _) = r
        .render(ctx, &camera, SPHERE_PX, SPHERE_PX, technique, None)
        .unwrap_or_else(|e| panic!("{technique}: {e}"));
    read_rgba_f32(ctx, &out.scene).unwrap()
}

/// Which spread of the per-channel errors [`check_techniques`] holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spread {
    Largest,
    Percentile99,
}

/// Renders `scene` in every technique and holds each to `want` (x, y,
/// reference radiance): the error of each channel relative to max(reference,
/// 0.02), its mean within `limits.0` and its `spread` within `limits.1`; prints
/// one line per technique, starting with `what`.
pub fn check_techniques(
    ctx: &GpuContext,
    what: &str,
    scene: &Scene,
    want: &[(u32, u32, Vec3)],
    spread: Spread,
    limits: (f32, f32),
) {
    for technique in Technique::ALL {
        let mut errs = channel_errors(&render(ctx, scene, technique), want);
        errs.sort_by(f32::total_cmp);
        let mean = errs.iter().sum::<f32>() / errs.len() as f32;
        let (name, top) = match spread {
            Spread::Largest => ("largest", errs[errs.len() - 1]),
            Spread::Percentile99 => ("99th percentile", errs[errs.len() * 99 / 100]),
        };
        eprintln!(
            "{what}, {technique}: mean {:.3} %, {name} {:.3} % over {} pixels",
            mean * 100.0,
            top * 100.0,
            want.len()
        );
        assert!(
            mean <= limits.0 && top <= limits.1,
            "{what}, {technique}: mean {mean}, {name} {top}"
        );
    }
}

/// The value of setting `name` of material `m`'s surface (panics if unset).
pub fn param(m: &Material, name: &str) -> Vec<f64> {
    m.surface
        .params
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v.clone())
        .unwrap_or_else(|| panic!("{name} not set"))
}

/// The error of each channel of `px` (a [`render`] image) against `want` (x,
/// y, reference), relative to max(reference, 0.02).
pub fn channel_errors(px: &[[f32; 4]], want: &[(u32, u32, Vec3)]) -> Vec<f32> {
    want.iter()
        .flat_map(|(x, y, w)| {
            let got = px[(y * SPHERE_PX + x) as usize];
            (0..3).map(move |c| (got[c] - w[c]).abs() / w[c].max(0.02))
        })
        .collect()
}

/// Mean and largest of [`channel_errors`].
pub fn relative_errors(px: &[[f32; 4]], want: &[(u32, u32, Vec3)]) -> (f32, f32) {
    let errs = channel_errors(px, want);
    let mean = errs.iter().map(|e| f64::from(*e)).sum::<f64>() / errs.len().max(1) as f64;
    (mean as f32, errs.iter().copied().fold(0.0, f32::max))
}
