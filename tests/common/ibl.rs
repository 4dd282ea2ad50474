//! CPU references of image-based lighting, written from the definitions (no
//! split sum, no prefiltering): integrals over the texels of an equirectangular
//! environment map, each texel a direction (its centre) and a solid angle
//! (`Equirect::texel_solid_angle`), and the cube-map face directions of the
//! Vulkan / WebGPU face selection table.
#![allow(dead_code)]

use super::brdf::{
    for_each_ggx_grid_direction, gltf_spec_brdf, specular_albedo_ggx_grid, OracleCamera,
};
use fxgraph::render::environment::bright::BrightCell;
use fxgraph::scene::environment::{direction_to_uv, uv_to_direction, Equirect};
use fxgraph::scene::{Camera, Environment, Material, Scene, ShaderBinding};
use glam::{Mat4, Vec3};
use std::f32::consts::PI;

/// A texel: its centre's direction, its radiance, its solid angle.
pub type Texel = (Vec3, Vec3, f32);

/// Every texel of `map`.
pub fn texels(map: &Equirect) -> Vec<Texel> {
    let mut out = Vec::with_capacity(map.texels.len());
    for y in 0..map.height {
        let omega = map.texel_solid_angle(y);
        for x in 0..map.width {
            let d = uv_to_direction(
                (x as f32 + 0.5) / map.width as f32,
                (y as f32 + 0.5) / map.height as f32,
            );
            out.push((d, map.at(x, y), omega));
        }
    }
    out
}

/// `map` halved until it is at most `width` texels wide.
pub fn downsampled(map: &Equirect, width: u32) -> Equirect {
    let mut m = map.clone();
    while m.width > width {
        m = m.halved();
    }
    m
}

/// Irradiance / π at a surface of unit normal `n`: ∫ L(l) max(n·l, 0) dω / π.
pub fn irradiance(t: &[Texel], n: Vec3) -> Vec3 {
    t.iter()
        .map(|(l, le, omega)| *le * (n.dot(*l).max(0.0) * omega))
        .sum::<Vec3>()
        / PI
}

/// The GGX-weighted mean radiance about `n` that a prefiltered level of
/// perceptual roughness `roughness` holds (the split sum's n = v = r): the
/// glTF BRDF's f cos at n = v, D(n·h) G1(n·l) / 4 (height-correlated Smith
/// with Λ(v) = 0), as the weight:
/// ∫ L(l) D(n·h) G1(n·l) dω / ∫ D(n·h) G1(n·l) dω, h = normalize(n + l),
/// G1(c) = 2 / (1 + √(1 + α² (1 − c²) / c²)).
pub fn ggx_prefiltered(t: &[Texel], n: Vec3, roughness: f32) -> Vec3 {
    let a = (roughness * roughness).max(1e-3);
    let a2 = a * a;
    let g1 = |c: f32| 2.0 / (1.0 + (1.0 + a2 * (1.0 - c * c) / (c * c)).sqrt());
    let mut sum = Vec3::ZERO;
    let mut w = 0.0f64;
    for (l, le, omega) in t {
        let ndl = n.dot(*l);
        if ndl <= 0.0 {
            continue;
        }
        let h = (n + *l).normalize();
        let ndh = n.dot(h);
        let dd = ndh * ndh * (a2 - 1.0) + 1.0;
        let k = a2 / (PI * dd * dd) * g1(ndl) * omega;
        sum += *le * k;
        w += f64::from(k);
    }
    sum / w.max(1e-30) as f32
}

/// A glTF metallic-roughness surface: what the radiance oracles below take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MetalRough {
    pub base: Vec3,
    pub metallic: f32,
    pub roughness: f32,
}

impl MetalRough {
    /// The specular reflectance at normal incidence: `mix(0.04, base, metallic)`.
    pub fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base, self.metallic)
    }

    /// The diffuse colour: `mix(base, 0, metallic)`.
    pub fn c_diff(&self) -> Vec3 {
        self.base * (1.0 - self.metallic)
    }
}

/// The reflected radiance of a glTF metallic-roughness surface lit by the
/// environment `t`: the glTF 2.0 BRDF (Appendix B, [`gltf_spec_brdf`])
/// integrated over every texel, plus the multiple-scattering lobe of
/// Fdez-Agüera (2019) the renderer adds to compensate the energy single
/// scattering loses: `Fms · Ems · E/π` with `Ess` (F0 = 1) and `Fss·Ess` (the
/// surface's F0) integrated here over the hemisphere ([`scattering`]), `Favg = F0 + (1 − F0)/21`,
/// `Fms = Fss·Ess · Favg / (1 − (1 − Ess) Favg)`.
pub fn reference_radiance(t: &[Texel], s: MetalRough, n: Vec3, v: Vec3) -> Vec3 {
    let brdf = |l: Vec3| gltf_spec_brdf(s.base, s.metallic, s.roughness, n, v, l);
    let single: Vec3 = t.iter().map(|(l, le, omega)| *le * *omega * brdf(*l)).sum();
    let (_, fms_ems) = scattering(s.f0(), s.roughness, n, v);
    single + fms_ems * irradiance(t, n)
}

/// [`reference_radiance`] of a metal (metallic 1) with the single-scattering
/// integral sampled instead of summed over texels: on a `steps` × 2·`steps`
/// grid uniform in GGX's distribution of the half vector, each direction
/// reading `map`'s texel (the map as constant per texel, as the texel sum takes
/// it). For lobes narrower than a texel (roughness 0.05: α = 0.0025, a third
/// of a 512-wide map's texel), where the texel sum evaluates the BRDF at a few
/// texel centres and misses or overweighs its peak (56 % off at 0.05 under
/// city.exr). Not for maps with very bright small areas at larger roughness:
/// few samples reach the lobe's far tails, and under studio.exr at 0.1 two
/// grids (128² and 384²) differ by 15 %.
pub fn reference_radiance_sampled(
    map: &Equirect,
    t: &[Texel],
    s: MetalRough,
    n: Vec3,
    v: Vec3,
    steps: u32,
) -> Vec3 {
    assert!(s.metallic == 1.0, "the sampled reference is for metals");
    let mut single = Vec3::ZERO;
    for_each_ggx_grid_direction(s.roughness, n, v, steps, |l, w| {
        let f = gltf_spec_brdf(s.base, 1.0, s.roughness, n, v, l);
        let (u, y) = direction_to_uv(l);
        let x = ((u * map.width as f32) as u32).min(map.width - 1);
        let y = ((y * map.height as f32) as u32).min(map.height - 1);
        single += map.at(x, y) * f * w;
    });
    let (_, fms_ems) = scattering(s.f0(), s.roughness, n, v);
    single + fms_ems * irradiance(t, n)
}

/// The unit direction of texel centre (x, y) of face `face` (+X, −X, +Y, −Y, +Z,
/// −Z) of a cube map of side `size`, from the Vulkan specification's cube map
/// face selection table (sc, tc = 2 (x + 0.5) / size − 1, 2 (y + 0.5) / size − 1,
/// rows down).
pub fn cube_texel_direction(face: u32, x: u32, y: u32, size: u32) -> Vec3 {
    let sc = 2.0 * (x as f32 + 0.5) / size as f32 - 1.0;
    let tc = 2.0 * (y as f32 + 0.5) / size as f32 - 1.0;
    // the table gives, per face, (major axis, sc, tc) in terms of the direction r:
    // +X: rx, -rz, -ry   -X: -rx, rz, -ry   +Y: ry, rx, rz   -Y: -ry, rx, -rz
    // +Z: rz, rx, -ry    -Z: -rz, -rx, -ry; solved for r with |major| = 1
    let r = match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    };
    r.normalize()
}

/// Side of the test images of one sphere.
pub const SPHERE_PX: u32 = 96;

/// A unit sphere at the origin with a glTF metallic-roughness material, lit by
/// `env` alone (no punctual light).
pub fn env_sphere(base: Vec3, metallic: f32, roughness: f32, env: Environment) -> Scene {
    let material = Material::new(
        "sphere",
        ShaderBinding::new("standard")
            .with(
                "base_color",
                &[base.x as f64, base.y as f64, base.z as f64, 1.0],
            )
            .with("metallic", &[metallic as f64])
            .with("roughness", &[roughness as f64]),
        ShaderBinding::new("cook_torrance"),
    );
    let name = format!("sphere (metallic {metallic}, roughness {roughness})");
    let mesh = fxgraph::scene::builtin::uv_sphere(192, 96);
    let mut scene = super::scenes::one_object(name, "sphere", mesh, material, Mat4::IDENTITY);
    scene.environment = Some(env);
    scene
}

/// The camera of [`env_sphere`] (on +Z, looking at the origin) and its oracle twin.
pub fn sphere_camera() -> (Camera, OracleCamera) {
    super::brdf::sphere_camera(SPHERE_PX)
}

/// The pixels well inside the sphere (the ray and its four neighbours' rays hit),
/// every `stride`-th in x and y: (x, y, normal, direction towards the eye).
pub fn interior_pixels(o: &OracleCamera, stride: u32) -> Vec<(u32, u32, Vec3, Vec3)> {
    let hit = |x: u32, y: u32| {
        let (eye, d) = o.ray(x, y);
        super::brdf::ray_sphere(eye, d, Vec3::ZERO, 1.0).map(|t| (eye + d * t, d))
    };
    let mut out = Vec::new();
    for y in (1..o.height - 1).step_by(stride as usize) {
        for x in (1..o.width - 1).step_by(stride as usize) {
            let inside = [(x, y), (x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]
                .iter()
                .all(|&(a, b)| hit(a, b).is_some());
            if let (true, Some((p, d))) = (inside, hit(x, y)) {
                out.push((x, y, p.normalize(), -d));
            }
        }
    }
    out
}

/// The renderer's model of the same light, computed here from its definition
/// (docs/environment.md, "Shading"): the split sum's albedos with the
/// multiple-scattering lobe, `Fss·Ess · P + Fms·Ems · E/π + c_diff (1 −
/// Fss·Ess − Fms·Ems) E/π`, where `P` is the lobe model's weighted sum of
/// [`ggx_prefiltered`] reads ([`model_prefiltered`]) and the albedos are
/// brute-force hemisphere integrals. What it differs by from
/// [`reference_radiance`] is the model's own error.
pub fn split_sum_radiance(t: &[Texel], s: MetalRough, n: Vec3, v: Vec3) -> Vec3 {
    let (fss_ess, fms_ems) = scattering(s.f0(), s.roughness, n, v);
    let e = irradiance(t, n);
    fss_ess * model_prefiltered(t, s.roughness, n, v)
        + fms_ems * e
        + s.c_diff() * (Vec3::ONE - fss_ess - fms_ems) * e
}

/// The renderer's model with the map split by
/// [`fxgraph::render::environment::bright::split`]: [`split_sum_radiance`]'s
/// terms with the lobe model reading the `residual` texels (the specular levels
/// from 1 on hold the residual) and the irradiance the `whole` map's, plus the
/// bright cells' light under the glTF BRDF's single-scattering specular term,
/// each cell a direction with the lobe widened by its angular radius
/// (environment.wgsl `fx_env_bright_specular`). Roughness ≥ 0.1: the cells'
/// share is 1 there.
pub fn bright_split_radiance(
    whole: &[Texel],
    residual: &[Texel],
    cells: &[BrightCell],
    s: MetalRough,
    n: Vec3,
    v: Vec3,
) -> Vec3 {
    assert!(
        s.roughness >= 0.1,
        "the cells' share below roughness 0.1 is not modelled here"
    );
    let (fss_ess, fms_ems) = scattering(s.f0(), s.roughness, n, v);
    let e = irradiance(whole, n);
    let alpha = (s.roughness * s.roughness).max(1e-3);
    let bright: Vec3 = cells
        .iter()
        .map(|c| {
            let l = Vec3::from_slice(&c.direction_radius[..3]);
            let widened = (alpha * alpha + 0.25 * c.direction_radius[3].powi(2)).sqrt();
            let power = Vec3::from_slice(&c.power_omega[..3]);
            power * specular_term(s.f0(), alpha, widened, n, v, l)
        })
        .sum();
    fss_ess * model_prefiltered(residual, s.roughness, n, v)
        + fms_ems * e
        + s.c_diff() * (Vec3::ONE - fss_ess - fms_ems) * e
        + bright
}

/// The glTF BRDF's specular term times n·l: Schlick's F, GGX D of `d_alpha`,
/// height-correlated Smith V of `alpha`.
fn specular_term(f0: Vec3, alpha: f32, d_alpha: f32, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let ndl = n.dot(l);
    if ndl <= 0.0 {
        return Vec3::ZERO;
    }
    let ndv = n.dot(v).max(1e-4);
    let h = (v + l).normalize();
    let da2 = d_alpha * d_alpha;
    let dd = n.dot(h).max(0.0).powi(2) * (da2 - 1.0) + 1.0;
    let d = da2 / (PI * dd * dd);
    let a2 = alpha * alpha;
    let vis = 0.5
        / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt() + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt())
            .max(1e-12);
    let f = f0 + (Vec3::ONE - f0) * (1.0 - v.dot(h).max(0.0)).powi(5);
    f * (d * vis * ndl)
}

/// The lobe's dominant direction: the mirror direction leaned towards the
/// normal (Lagarde and de Rousiers 2014, listing 22; α = roughness²).
pub fn dominant_direction(roughness: f32, n: Vec3, v: Vec3) -> Vec3 {
    let a = roughness * roughness;
    let gloss = 1.0 - a;
    let mirror = 2.0 * n.dot(v) * n - v;
    n.lerp(mirror, gloss * (gloss.sqrt() + a)).normalize()
}

/// The prefiltered radiance of the lobe model (fxgraph's `lobe_taps`: per
/// tap an offset `o` from the dominant direction `r` along `t`, the in-plane
/// unit vector ⟂ r towards n, a roughness and a weight), each tap an exact
/// convolution of the map ([`ggx_prefiltered`]).
pub fn model_prefiltered(t: &[Texel], roughness: f32, n: Vec3, v: Vec3) -> Vec3 {
    let r = dominant_direction(roughness, n, v);
    let across = (n - n.dot(r) * r).normalize_or_zero();
    let taps = fxgraph::render::environment::lobe_taps(n.dot(v).max(1e-4), roughness);
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
    for [o, rho, w] in taps {
        sum += w * ggx_prefiltered(t, (r + o * across).normalize(), rho);
        weight += w;
    }
    sum / weight
}

/// `(Fss·Ess, Fms·Ems)` of Fdez-Agüera (2019) at a point of normal `n` seen
/// from `v`: the single-scattering specular albedo for `f0` and the
/// multiple-scattering lobe's weight, from the glTF BRDF integrated over the
/// hemisphere on a grid uniform in GGX's distribution of the half vector
/// ([`specular_albedo_ggx_grid`], 128 × 256 points), `Ess` its albedo for F0 =
/// 1, `Ems = 1 − Ess`, `Favg = F0 + (1 − F0)/21`, `Fms = Fss·Ess · Favg / (1 −
/// Ems·Favg)`. An angle grid (1.9° or 0.7° steps, as this used before) misses
/// a smooth lobe at grazing view: at roughness 0.1 and n·v = 0.08 it gave Ess
/// 0.03 instead of 0.76, so the reference added the irradiance back as if the
/// surface had lost 97 % of its energy (tests/environment.rs checks the grid).
pub fn scattering(f0: Vec3, roughness: f32, n: Vec3, v: Vec3) -> (Vec3, Vec3) {
    let mu = n.dot(v).clamp(1e-4, 1.0);
    let v_local = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let ess = specular_albedo_ggx_grid(Vec3::ONE, roughness, v_local, SCATTERING_STEPS);
    let fss_ess = specular_albedo_ggx_grid(f0, roughness, v_local, SCATTERING_STEPS);
    let ems = 1.0 - ess.x;
    let f_avg = f0 + (Vec3::ONE - f0) / 21.0;
    let fms = fss_ess * f_avg / (Vec3::ONE - ems * f_avg);
    (fss_ess, fms * ems)
}

/// Rows of [`scattering`]'s grid (its columns are twice as many).
pub const SCATTERING_STEPS: u32 = 128;

pub fn corpus(rel: &str) -> std::path::PathBuf {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/corpus")
        .join(rel);
    assert!(
        p.exists(),
        "{} is missing: the environment tests need the corpus (../shared/corpus)",
        p.display()
    );
    p
}
