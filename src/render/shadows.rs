//! Shadow maps, the host side: the shadow options, which lights get maps this
//! frame (the layer budget), cascade splits and fitting, and the light matrices.
//! Plain CPU code; `shadow_pass.rs` renders the maps and `shaders/shadow.wgsl`
//! samples them.
//!
//! Every map is one layer of a single `Depth32Float` 2D array texture:
//! - directional light: [`CASCADES`] cascades (practical split scheme), each an
//!   orthographic map over the bounding sphere of its slice of the view
//!   frustum, its depth range over the scene's bounds so that casters outside
//!   the slice still cast; `cascades.rs` places the map (by default on a
//!   world-fixed set of squares, so that it stays while the camera moves);
//! - spot light: one perspective map (fov = 2 × outer angle);
//! - point light: six 90° perspective maps along the world axes (a cube map as
//!   six layers; the shader picks the face by the major axis).
//!
//! The matrices are built in world space (so a moving camera does not rotate or
//! shift the texel grid: no shimmering) and stored as view space → light clip,
//! because lights and shading points are in view space in the shaders.

use super::cascades;
use super::cli_names::cli_names;
use super::gpu_types::{mat_array, GpuLight, KIND_DIRECTIONAL, KIND_POINT, KIND_SPOT};
use crate::scene::{look_to_rh, perspective_rh, Aabb, Camera};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

/// How shadows are filtered (or whether there are any).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum ShadowMode {
    /// No shadow maps: every light reaches every point (the renderer before
    /// shadows).
    Off,
    /// One depth comparison per lookup (nearest texel): hard, aliased edges.
    Hard,
    /// Percentage-closer filtering: 3×3 bilinear comparison taps (a 4×4 texel
    /// footprint), soft edges a few texels wide.
    #[default]
    Pcf,
}

cli_names!(
    ShadowMode {
        Off => "off",
        Hard => "hard",
        Pcf => "pcf",
    },
    parse = "unknown shadow mode `{}` (off, hard or pcf)"
);

impl ShadowMode {
    /// The filter id the shaders read from `FxLight::shadow_filter`.
    pub(crate) fn filter_id(self) -> u32 {
        match self {
            ShadowMode::Off => 0,
            ShadowMode::Hard => 1,
            ShadowMode::Pcf => 2,
        }
    }
}

/// Default side of a shadow map (texels).
pub const DEFAULT_SHADOW_SIZE: u32 = 2048;
/// Smallest and largest `shadow_size` accepted.
pub const MIN_SHADOW_SIZE: u32 = 256;
pub const MAX_SHADOW_SIZE: u32 = 8192;
/// Default per-frame budget of shadow-map layers (6 point lights, or 6
/// directional lights, or mixes).
pub const DEFAULT_SHADOW_LAYERS: u32 = 24;
/// Cascades of a directional light.
pub const CASCADES: usize = 4;
/// Weight of the logarithmic split in the practical split scheme (the rest is
/// uniform): 1 gives the near cascades all the resolution, 0 wastes it far away.
const SPLIT_LAMBDA: f32 = 0.75;
/// Texels kept free at the border of point-light faces (and added round the
/// cascade spheres) so that filter taps near an edge stay inside the map.
const BORDER_TEXELS: f32 = 3.0;

/// The layers a light of `kind` needs.
pub(crate) fn layers_of(kind: u32) -> u32 {
    match kind {
        KIND_DIRECTIONAL => CASCADES as u32,
        KIND_SPOT => 1,
        KIND_POINT => 6,
        _ => 0,
    }
}

/// `FxShadowLayer` in `shaders/shadow.wgsl` (80 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub(crate) struct GpuShadowLayer {
    /// View space → the light's clip space (depth 0..1).
    pub clip_from_view: [f32; 16],
    /// Directional cascades: the far end of the cascade as positive view depth;
    /// 0 for other lights.
    pub split: f32,
    /// World size of one texel: absolute (orthographic), or at unit distance
    /// from the light (perspective); scales the normal offset.
    pub texel: f32,
    /// 1 for perspective maps (spot, point).
    pub perspective: u32,
    pub _pad: u32,
}

/// What the planner needs to know about the frame.
pub(crate) struct ShadowFrame<'a> {
    pub camera: &'a Camera,
    /// World position and unit direction of each light (`LightLists::world`).
    pub world: &'a [(Vec3, Vec3)],
    pub view: Mat4,
    pub aspect: f32,
    /// World bounds of every shadow caster.
    pub bounds: Aabb,
    pub mode: ShadowMode,
    pub size: u32,
    pub budget: u32,
    /// Directional cascades by the stable fit (`cascades.rs`), or fitted
    /// afresh every frame (`RendererOptions::stable_cascades`).
    pub stable: bool,
}

/// The frame's shadow layers.
#[derive(Debug, Default)]
pub(crate) struct ShadowPlan {
    pub layers: Vec<GpuShadowLayer>,
    /// World → light clip of each layer (the depth pass draws with these).
    pub clip_from_world: Vec<Mat4>,
    /// Lights that should have had shadows but did not fit the budget.
    pub lights_lost: usize,
    /// Layers those lights would have needed.
    pub layers_lost: u32,
}

/// Chooses the lights that get shadow maps (directional lights first, then by
/// importance: peak intensity over distance to the camera), gives each its first
/// layer and layer count in `lights`, and builds every layer.
pub(crate) fn plan(lights: &mut [GpuLight], f: &ShadowFrame) -> ShadowPlan {
    let mut out = ShadowPlan::default();
    if f.mode == ShadowMode::Off || f.bounds.is_empty() {
        return out;
    }
    let mut order: Vec<(usize, bool, f32)> = lights
        .iter()
        .enumerate()
        .filter(|(_, l)| layers_of(l.kind) > 0 && l.casts_shadows != 0)
        .map(|(i, l)| {
            let peak = Vec3::from(l.color).max_element();
            let distance = Vec3::from(l.position).length().max(1e-3);
            let importance = if l.kind == KIND_DIRECTIONAL {
                peak
            } else {
                peak / distance
            };
            (i, l.kind == KIND_DIRECTIONAL, importance)
        })
        .collect();
    order.sort_by(|a, b| b.1.cmp(&a.1).then(b.2.total_cmp(&a.2)));
    let view_inv = f.view.inverse();
    for (i, _, _) in order {
        let l = &mut lights[i];
        let need = layers_of(l.kind);
        if out.layers.len() as u32 + need > f.budget {
            out.lights_lost += 1;
            out.layers_lost += need;
            continue;
        }
        let first = out.layers.len() as u32;
        let place = f.world[i];
        let built = match l.kind {
            KIND_DIRECTIONAL => directional(place.1, f, &view_inv),
            KIND_SPOT => vec![spot(l, place, f, &view_inv)],
            _ => point(l, place.0, f, &view_inv),
        };
        for (clip_from_world, layer) in built {
            out.clip_from_world.push(clip_from_world);
            out.layers.push(layer);
        }
        l.shadow_first = first;
        l.shadow_count = need;
        l.shadow_filter = f.mode.filter_id();
    }
    out
}

fn layer(
    clip_from_world: Mat4,
    view_inv: &Mat4,
    split: f32,
    texel: f32,
    perspective: bool,
) -> (Mat4, GpuShadowLayer) {
    (
        clip_from_world,
        GpuShadowLayer {
            clip_from_view: mat_array(clip_from_world * *view_inv),
            split,
            texel,
            perspective: u32::from(perspective),
            _pad: 0,
        },
    )
}

/// An up vector not parallel to `dir`.
fn up_for(dir: Vec3) -> Vec3 {
    if dir.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Split depths (positive view depths) of the practical split scheme between
/// `near` and `far`: `CASCADES + 1` values, the first `near`, the last `far`.
pub(crate) fn cascade_splits(near: f32, far: f32) -> [f32; CASCADES + 1] {
    let mut s = [0.0; CASCADES + 1];
    for (i, v) in s.iter_mut().enumerate() {
        let t = i as f32 / CASCADES as f32;
        let log = near * (far / near).powf(t);
        let uniform = near + (far - near) * t;
        *v = SPLIT_LAMBDA * log + (1.0 - SPLIT_LAMBDA) * uniform;
    }
    s[0] = near;
    s[CASCADES] = far;
    s
}

/// The smallest sphere (centre on the view axis, as positive depth, and radius)
/// holding the slice of a symmetric view frustum between depths `d0 < d1`, with
/// `k = tan(fov_y / 2) · sqrt(1 + aspect²)` the corner's distance from the axis
/// per unit depth. It depends on the depths alone, not on the camera's
/// orientation, so a turning camera keeps the cascade's size.
pub(crate) fn slice_sphere(d0: f32, d1: f32, k: f32) -> (f32, f32) {
    let k2 = k * k;
    let zc = ((d0 + d1) * (1.0 + k2) * 0.5).min(d1);
    let r0 = ((zc - d0).powi(2) + k2 * d0 * d0).sqrt();
    let r1 = ((d1 - zc).powi(2) + k2 * d1 * d1).sqrt();
    (zc, r0.max(r1))
}

/// The cascades of a directional light: split the view depth, bound each
/// slice with a sphere, and place its map (`cascades.rs`: the stable or the
/// per-frame fit).
fn directional(dir: Vec3, f: &ShadowFrame, view_inv: &Mat4) -> Vec<(Mat4, GpuShadowLayer)> {
    let cam = f.camera;
    let light_view = look_to_rh(Vec3::ZERO, dir, up_for(dir));
    // the casters' box in light space (light space looks down -z)
    let scene = f.bounds.transformed(&light_view);
    let far = cascade_far(f).min(cam.far).max(cam.near * 1.01);
    let splits = cascade_splits(cam.near, far);
    let k = (cam.fov_y * 0.5).tan() * (1.0 + f.aspect * f.aspect).sqrt();
    let size = f.size as f32;
    // the border texels round each sphere (a radius grows by this factor)
    let border = size / (size - 2.0 * BORDER_TEXELS);
    (0..CASCADES)
        .map(|i| {
            let (zc, r) = slice_sphere(splits[i], splits[i + 1], k);
            let r = r * size / (size - 2.0 * BORDER_TEXELS);
            let center = view_inv.transform_point3(Vec3::new(0.0, 0.0, -zc));
            let c = light_view.transform_point3(center);
            let square = if f.stable {
                let empty = cascades::misses(center, r, &f.bounds);
                cascades::stable(c, r, &scene, (size, border), empty)
            } else {
                cascades::refit(c, r, &scene, size)
            };
            layer(
                square.clip_from_light() * light_view,
                view_inv,
                splits[i + 1],
                square.texel(size),
                false,
            )
        })
        .collect()
}

/// Where the cascades end: the scene's farthest corner (the per-frame fit:
/// no resolution for empty space), or the far side of its bounding sphere (the
/// stable fit: the same for every direction the camera looks).
fn cascade_far(f: &ShadowFrame) -> f32 {
    if f.stable {
        return cascades::stable_far(f.camera.eye, &f.bounds);
    }
    corners(&f.bounds)
        .iter()
        .map(|c| -f.view.transform_point3(*c).z)
        .fold(f32::NEG_INFINITY, f32::max)
}

/// Near plane of a light's perspective maps: close enough for casters near the
/// light, far enough for depth precision over the radius.
fn near_of(radius: f32) -> f32 {
    (radius * 2e-3).max(1e-4)
}

fn spot(
    l: &GpuLight,
    (pos, dir): (Vec3, Vec3),
    f: &ShadowFrame,
    view_inv: &Mat4,
) -> (Mat4, GpuShadowLayer) {
    let outer = l.cos_outer.clamp(-1.0, 1.0).acos();
    let size = f.size as f32;
    // a border of a few texels round the cone for the filter taps
    let half = ((outer.tan() * size / (size - 2.0 * BORDER_TEXELS)).atan()).min(85f32.to_radians());
    let proj = perspective_rh(2.0 * half, 1.0, near_of(l.radius), l.radius);
    let texel = 2.0 * half.tan() / size;
    layer(
        proj * look_to_rh(pos, dir, up_for(dir)),
        view_inv,
        0.0,
        texel,
        true,
    )
}

/// The face directions of a point light's cube, in the shader's order.
pub(crate) const CUBE_FACES: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

fn point(l: &GpuLight, pos: Vec3, f: &ShadowFrame, view_inv: &Mat4) -> Vec<(Mat4, GpuShadowLayer)> {
    let size = f.size as f32;
    // 90° plus a border: lookups near a face's edge filter inside that face
    let tan_half = size / (size - 2.0 * BORDER_TEXELS);
    let proj = perspective_rh(2.0 * tan_half.atan(), 1.0, near_of(l.radius), l.radius);
    let texel = 2.0 * tan_half / size;
    CUBE_FACES
        .iter()
        .map(|&d| {
            layer(
                proj * look_to_rh(pos, d, up_for(d)),
                view_inv,
                0.0,
                texel,
                true,
            )
        })
        .collect()
}

fn corners(b: &Aabb) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// Where view-space point `p` lands in `layer`: (u, v) in 0..1 (v down) and depth.
#[cfg(test)]
fn project(layer: &GpuShadowLayer, p: Vec3) -> Vec3 {
    let c = Mat4::from_cols_array(&layer.clip_from_view) * p.extend(1.0);
    let n = c.truncate() / c.w;
    Vec3::new(n.x * 0.5 + 0.5, 0.5 - n.y * 0.5, n.z)
}

#[cfg(test)]
#[path = "shadows_tests.rs"]
mod tests;
