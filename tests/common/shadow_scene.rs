//! The shadow test scene of `tests/shadows.rs` and its CPU oracle: a white
//! Lambertian box floating over a white plane, a camera, one light of each kind,
//! and per pixel the ground point under the pixel centre, its analytic radiance
//! and whether a ray from it to the light hits the box.

use super::brdf::illuminance;
use fxgraph::scene::{Camera, Instance, Light, Material, Scene, ShaderBinding};
use glam::{Mat4, Vec3, Vec4};
use std::f32::consts::PI;

pub const W: u32 = 160;
pub const H: u32 = 120;
/// Half the side of the ground plane (y = 0).
pub const GROUND: f32 = 8.0;
/// The floating box: centre and half size.
pub const BOX_CENTER: Vec3 = Vec3::new(0.0, 1.5, 0.0);
pub const BOX_HALF: Vec3 = Vec3::new(0.6, 0.5, 0.6);

pub fn scene(light: Light) -> Scene {
    let mut s = Scene {
        name: "box over a plane".into(),
        ..Default::default()
    };
    s.meshes.push(fxgraph::scene::builtin::grid_plane(4));
    s.meshes
        .push(fxgraph::scene::builtin::box_mesh(BOX_HALF * 2.0));
    s.materials.push(Material::new(
        "white lambert",
        ShaderBinding::new("standard").with("base_color", &[1.0, 1.0, 1.0, 1.0]),
        ShaderBinding::new("lambert"),
    ));
    s.instances.push(Instance {
        name: "ground".into(),
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::new(2.0 * GROUND, 1.0, 2.0 * GROUND)),
        ..Default::default()
    });
    s.instances.push(Instance {
        name: "box".into(),
        mesh: 1,
        material: 0,
        transform: Mat4::from_translation(BOX_CENTER),
        ..Default::default()
    });
    s.lights.push(light);
    s
}

pub fn camera() -> Camera {
    Camera {
        eye: Vec3::new(1.0, 7.0, 7.5),
        target: Vec3::new(0.0, 0.0, 0.5),
        up: Vec3::Y,
        fov_y: 50f32.to_radians(),
        near: 0.1,
        far: 40.0,
    }
}

pub fn directional() -> Light {
    // π lux: a white Lambertian surface facing it has radiance 1
    Light::directional(Vec3::new(0.45, -1.0, 0.3), Vec3::ONE, PI)
}

pub fn spot() -> Light {
    Light::spot(
        Vec3::new(-1.0, 5.0, -0.5),
        Vec3::new(0.25, -1.0, 0.15),
        Vec3::ONE,
        60.0,
        14.0,
        0.55,
        0.75,
    )
}

pub fn point() -> Light {
    Light::point(Vec3::new(0.7, 3.6, -0.4), Vec3::ONE, 40.0, 14.0)
}

/// Writes `pixels` to tests/output/shadows_NAME.png for review.
pub fn save_review(name: &str, pixels: &[[f32; 4]]) {
    let name = format!("shadows_{}", name.replace(' ', "_"));
    super::renders::save_rgb_review(&name, (W, H), pixels);
}

/// Entry and exit distances of the ray `o + t d` through the box, if it hits.
pub fn hit_box(o: Vec3, d: Vec3) -> Option<(f32, f32)> {
    let (lo, hi) = (BOX_CENTER - BOX_HALF, BOX_CENTER + BOX_HALF);
    let inv = d.recip();
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    (far >= near.max(0.0)).then_some((near, far))
}

/// What the oracle knows about one pixel of the ground.
#[derive(Clone, Copy)]
pub struct Ground {
    /// Radiance without shadows: E · cos θ / π (white Lambert).
    pub lit: f32,
    pub shadowed: bool,
}

/// Per pixel: the ground point under the pixel centre (None: the box or nothing)
/// with its analytic lit radiance and whether the box blocks the light.
pub fn oracle(light: &Light) -> Vec<Option<Ground>> {
    oracle_wrap(light, 0.0)
}

/// [`oracle`] for the user lighting shader `wrap_lambert` (docs/examples):
/// `E · max((n·l + w) / (1 + w)², 0) / π`; `w = 0` is Lambert.
pub fn oracle_wrap(light: &Light, wrap: f32) -> Vec<Option<Ground>> {
    let cam = camera();
    let inv = (cam.proj(W as f32 / H as f32) * cam.view()).inverse();
    let mut out = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let ndc_x = (x as f32 + 0.5) / W as f32 * 2.0 - 1.0;
            let ndc_y = 1.0 - (y as f32 + 0.5) / H as f32 * 2.0;
            let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let d = (far.truncate() / far.w - cam.eye).normalize();
            let t = -cam.eye.y / d.y;
            let p = cam.eye + d * t;
            let on_ground = d.y < 0.0 && p.x.abs() < GROUND && p.z.abs() < GROUND;
            let box_first = hit_box(cam.eye, d).is_some_and(|(near, _)| near < t);
            if !on_ground || box_first {
                out.push(None);
                continue;
            }
            let Some((l, e)) = illuminance(light, p, true) else {
                out.push(Some(Ground {
                    lit: 0.0,
                    shadowed: false,
                }));
                continue;
            };
            let lit = e.x * ((l.y + wrap) / ((1.0 + wrap) * (1.0 + wrap))).max(0.0) / PI;
            let reach = match light.kind {
                fxgraph::scene::LightKind::Directional => f32::INFINITY,
                _ => (light.position - p).length(),
            };
            let shadowed = hit_box(p + l * 1e-4, l).is_some_and(|(near, _)| near < reach);
            out.push(Some(Ground { lit, shadowed }));
        }
    }
    out
}

/// Checks an image against the oracle on the ground pixels at least 2 px from
/// a shadow edge (and from the box and the ground's border): shadowed ones below
/// 0.1 × the lit value, lit ones within 3 % of it; at least 95 % must agree.
/// Returns (agreeing fraction, shadowed pixels, lit pixels).
pub fn check_against_oracle(name: &str, pixels: &[[f32; 4]], light: &Light) -> (f64, usize, usize) {
    check_against(name, pixels, &oracle(light))
}

pub fn check_against(
    name: &str,
    pixels: &[[f32; 4]],
    truth: &[Option<Ground>],
) -> (f64, usize, usize) {
    save_review(name, pixels);
    let max_lit = truth.iter().flatten().map(|g| g.lit).fold(0.0f32, f32::max);
    let at = |x: i32, y: i32| -> Option<Ground> {
        if x < 0 || y < 0 || x >= W as i32 || y >= H as i32 {
            return None;
        }
        truth[(y as u32 * W + x as u32) as usize]
    };
    let (mut agree, mut total, mut shadow_px, mut lit_px) = (0usize, 0usize, 0usize, 0usize);
    let mut worst_lit = 0.0f32;
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let Some(g) = at(x, y) else { continue };
            // skip dim pixels (outside a spot's cone, past the light's reach)
            if g.lit < 0.05 * max_lit {
                continue;
            }
            let interior = (-2..=2).all(|dy| {
                (-2..=2).all(|dx| at(x + dx, y + dy).is_some_and(|n| n.shadowed == g.shadowed))
            });
            if !interior {
                continue;
            }
            total += 1;
            let v = pixels[(y as u32 * W + x as u32) as usize][1];
            let ok = if g.shadowed {
                shadow_px += 1;
                v < 0.1 * g.lit
            } else {
                lit_px += 1;
                worst_lit = worst_lit.max((v - g.lit).abs() / g.lit);
                (v - g.lit).abs() <= 0.03 * g.lit
            };
            if !ok && total - agree < 6 {
                eprintln!(
                    "{name}: ({x}, {y}) {} where the oracle says {} (lit value {})",
                    v,
                    if g.shadowed { "shadow" } else { "lit" },
                    g.lit
                );
            }
            agree += usize::from(ok);
        }
    }
    let fraction = agree as f64 / total.max(1) as f64;
    eprintln!(
        "{name}: {agree}/{total} pixels agree ({:.2} %), {shadow_px} shadowed, {lit_px} lit, worst lit error {:.2} %",
        fraction * 100.0,
        worst_lit * 100.0
    );
    assert!(
        shadow_px >= 100 && lit_px >= 300,
        "{name}: too few pixels to judge"
    );
    assert!(
        fraction >= 0.95,
        "{name}: only {:.2} % agree",
        fraction * 100.0
    );
    (fraction, shadow_px, lit_px)
}
