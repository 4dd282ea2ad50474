//! Lights for one frame: frustum culling, ambient sum, and the classification of
//! point and spot lights into light-volume draws (Tang et al.): front faces when the
//! camera is outside the volume, back faces when inside, full screen when the
//! volume also crosses the far plane.

use super::clusters::{self, ClusterGrid, LightCulling};
use super::gpu_types::*;
use crate::scene::{Camera, Light, LightKind};
use glam::{Mat4, Vec3, Vec4};
use std::ops::Range;

/// Segments of the cone proxy.
pub(crate) const CONE_SEGMENTS: u32 = 16;
/// Spot lights wider than this (half-angle) use a sphere volume.
pub(crate) const MAX_CONE_ANGLE: f32 = 1.40;

/// The light volume proxies: a unit icosphere and a unit cone in one vertex and
/// one index buffer.
pub(crate) struct LightVolumes {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub sphere_indices: std::ops::Range<u32>,
    pub cone_indices: std::ops::Range<u32>,
    pub cone_base_vertex: i32,
    /// Scale of the icosphere so that it circumscribes the true sphere.
    pub sphere_scale: f32,
    /// Scale of the cone's polygonal base so that it circumscribes the circle.
    pub cone_poly_scale: f32,
}

impl LightVolumes {
    pub fn new(
        ctx: &crate::gpu::context::GpuContext,
    ) -> Result<LightVolumes, crate::gpu::context::GpuError> {
        use wgpu::util::DeviceExt;
        let sphere = crate::scene::builtin::icosphere(2);
        let cone = crate::scene::builtin::cone(CONE_SEGMENTS);
        let sphere_scale = 1.0 / crate::scene::builtin::inradius(&sphere);
        let cone_poly_scale = 1.0 / (std::f32::consts::PI / CONE_SEGMENTS as f32).cos();
        let mut vol_v: Vec<[f32; 3]> = sphere.positions.iter().map(|p| (*p).into()).collect();
        let cone_base_vertex = vol_v.len() as i32;
        vol_v.extend(cone.positions.iter().map(|p| <[f32; 3]>::from(*p)));
        let mut vol_i = sphere.indices.clone();
        let sphere_indices = 0..vol_i.len() as u32;
        vol_i.extend_from_slice(&cone.indices);
        let cone_indices = sphere_indices.end..vol_i.len() as u32;
        let (vertices, indices) = ctx.scoped("deferred light volumes", |device| {
            (
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("deferred light volume vertices"),
                    contents: bytemuck::cast_slice(&vol_v),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("deferred light volume indices"),
                    contents: bytemuck::cast_slice(&vol_i),
                    usage: wgpu::BufferUsages::INDEX,
                }),
            )
        })?;
        Ok(LightVolumes {
            vertices,
            indices,
            sphere_indices,
            cone_indices,
            cone_base_vertex,
            sphere_scale,
            cone_poly_scale,
        })
    }
}

/// The frame's light ranges in the visible-index buffer.
pub(crate) struct FrameLists {
    pub fullscreen: Range<u32>,
    pub sphere_out: Range<u32>,
    pub sphere_in: Range<u32>,
    pub cone_out: Range<u32>,
    pub cone_in: Range<u32>,
    /// The forward loop's (constant) light count.
    pub forward_lights: u32,
    /// Cluster lists are bound: one clustered full-screen light pass.
    pub clustered: bool,
}

/// Per-frame light lists (indices into the GPU light array).
#[derive(Debug, Default)]
pub(crate) struct LightLists {
    pub gpu: Vec<GpuLight>,
    /// World position and unit direction of each light of `gpu` (as
    /// classified; not the padding): the shadow maps are planned from these, so
    /// a light's layers are bit-stable while it stays put, whatever the camera
    /// does (`shadow_cache.rs`).
    pub world: Vec<(Vec3, Vec3)>,
    /// Sum of the ambient lights (colour × intensity).
    pub ambient: Vec3,
    pub forward: Vec<u32>,
    pub fullscreen: Vec<u32>,
    pub sphere_out: Vec<u32>,
    pub sphere_in: Vec<u32>,
    pub cone_out: Vec<u32>,
    pub cone_in: Vec<u32>,
    /// Lights that reach every pixel (directional), for the clustered pass.
    pub globals: Vec<u32>,
    /// Point and spot lights with the bounding sphere of what they light, for
    /// the clustered pass.
    pub locals: Vec<super::clusters::LocalLight>,
    /// Lights skipped because their intensity is zero, negative or not finite.
    pub dark: usize,
}

impl LightLists {
    /// Frustum culling and volume classification of the lights for one frame.
    pub(crate) fn classify(
        lights: &[Light],
        sphere_scale: f32,
        cone_poly_scale: f32,
        camera: &Camera,
        view: &Mat4,
        proj: &Mat4,
        aspect: f32,
    ) -> LightLists {
        let mut lists = LightLists::default();
        let half_fov = (camera.fov_y * 0.5).tan();
        let c = Classifier {
            planes: frustum_planes(proj),
            // distance from the eye to a corner of the near plane rectangle
            near_margin: camera.near * (1.0 + half_fov * half_fov * (1.0 + aspect * aspect)).sqrt(),
            far: camera.far,
            view: *view,
            scales: VolumeScales {
                sphere: sphere_scale,
                cone_poly: cone_poly_scale,
            },
        };
        for l in lights {
            let color = l.color * l.intensity;
            if color.max_element() <= 0.0 || !color.is_finite() {
                lists.dark += 1;
                continue;
            }
            let dir_view = view
                .transform_vector3(l.direction)
                .normalize_or(Vec3::NEG_Z);
            let g = directional_light(l, color, dir_view);
            let index = lists.gpu.len() as u32;
            match l.kind {
                LightKind::Ambient => {
                    lists.ambient += color;
                }
                LightKind::Directional => {
                    lists.push(l, g);
                    lists.fullscreen.push(index);
                    lists.globals.push(index);
                }
                LightKind::Point | LightKind::Spot { .. } => {
                    c.add_local(&mut lists, l, g, dir_view);
                }
            }
        }
        lists
    }

    /// Adds a visible light to the GPU lights, the world directions and the
    /// forward list.
    fn push(&mut self, l: &Light, g: GpuLight) {
        let index = self.gpu.len() as u32;
        self.gpu.push(g);
        self.world
            .push((l.position, l.direction.normalize_or(Vec3::NEG_Y)));
        self.forward.push(index);
    }
}

/// A light as a directional light (colour `color`, view-space direction
/// `dir_view`): what the other kinds start from.
pub(crate) fn directional_light(l: &Light, color: Vec3, dir_view: Vec3) -> GpuLight {
    GpuLight {
        position: [0.0; 3],
        radius: 0.0,
        color: color.into(),
        kind: KIND_DIRECTIONAL,
        direction: dir_view.into(),
        volume_scale: 1.0,
        atten: l.attenuation,
        cos_outer: -1.0,
        cos_inner: 1.0,
        cone_radius: 0.0,
        volume: VOLUME_FULLSCREEN,
        range: l.range.filter(|r| r.is_finite() && *r > 0.0).unwrap_or(0.0),
        // shadow maps are assigned afterwards (shadows::plan)
        casts_shadows: u32::from(l.casts_shadows),
        ..bytemuck::Zeroable::zeroed()
    }
}

/// The bounding spheres (view space) of a point or spot light: of the region
/// it lights (for culling) and of its proxy volume.
pub(crate) struct LightSpheres {
    pub cull: (Vec3, f32),
    pub proxy: (Vec3, f32),
}

/// The proxy scales of [`LightVolumes`]: a light's volume fields depend on
/// them, not on the camera.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VolumeScales {
    pub sphere: f32,
    pub cone_poly: f32,
}

/// What one frame's point and spot lights are classified against.
struct Classifier {
    planes: [Vec4; 6],
    /// Distance from the eye to a corner of the near plane rectangle.
    near_margin: f32,
    far: f32,
    view: Mat4,
    scales: VolumeScales,
}

impl Classifier {
    /// A point or spot light: culled against the frustum, else added to the
    /// forward and cluster lists and to the volume list its proxy needs
    /// (inside: it holds the camera or the near plane; full-screen when it
    /// also crosses the far plane).
    fn add_local(&self, lists: &mut LightLists, l: &Light, mut g: GpuLight, dir_view: Vec3) {
        let Some(radius) = local_radius(l) else {
            return;
        };
        let pos = self.view.transform_point3(l.position);
        g.position = pos.into();
        g.radius = radius;
        let LightSpheres {
            cull: (cull_center, cull_radius),
            proxy: (proxy_center, proxy_radius),
        } = shape_volume(l, &mut g, pos, dir_view, self.scales);
        let outside = self
            .planes
            .iter()
            .any(|p| p.truncate().dot(cull_center) + p.w < -cull_radius);
        if outside {
            return;
        }
        let inside = proxy_center.length() < proxy_radius + self.near_margin;
        let crosses_far = -proxy_center.z + proxy_radius > self.far * 0.999;
        let index = lists.gpu.len() as u32;
        lists.push(l, g);
        lists.locals.push(super::clusters::LocalLight {
            index,
            center: cull_center,
            radius: cull_radius,
        });
        let list = match (inside, crosses_far, g.volume) {
            (true, true, _) => &mut lists.fullscreen,
            (true, false, VOLUME_CONE) => &mut lists.cone_in,
            (true, false, _) => &mut lists.sphere_in,
            (false, _, VOLUME_CONE) => &mut lists.cone_out,
            (false, _, _) => &mut lists.sphere_out,
        };
        list.push(index);
    }
}

/// The radius of point or spot light `l` (capped at 10⁷), or `None` when it
/// has none (such a light is skipped).
pub(crate) fn local_radius(l: &Light) -> Option<f32> {
    let radius = l.radius();
    (!radius.is_nan() && radius > 0.0).then(|| radius.min(1e7))
}

/// Sets the kind, cone and proxy volume of a point or spot light at position
/// `pos` with unit direction `dir` (radius in `g`): a cone for spots up to
/// [`MAX_CONE_ANGLE`], else a sphere. Returns its bounding spheres, in the
/// space of `pos` and `dir` (view or world: a rigid motion moves them alike).
pub(crate) fn shape_volume(
    l: &Light,
    g: &mut GpuLight,
    pos: Vec3,
    dir: Vec3,
    scales: VolumeScales,
) -> LightSpheres {
    let radius = g.radius;
    // bounding sphere of the lit region (for culling) and of the proxy
    let mut cull = (pos, radius);
    let sphere = (pos, radius * scales.sphere);
    let LightKind::Spot { inner, outer } = l.kind else {
        g.kind = KIND_POINT;
        g.volume = VOLUME_SPHERE;
        g.volume_scale = scales.sphere;
        return LightSpheres {
            cull,
            proxy: sphere,
        };
    };
    let outer = outer.clamp(1e-3, std::f32::consts::FRAC_PI_2);
    let inner = inner.clamp(0.0, outer);
    g.kind = KIND_SPOT;
    g.cos_outer = outer.cos();
    g.cos_inner = inner.cos().max(g.cos_outer + 1e-4);
    if outer <= MAX_CONE_ANGLE {
        g.volume = VOLUME_CONE;
        g.cone_radius = radius * outer.tan() * scales.cone_poly;
        let (c, r) = cone_bounding_sphere(pos, dir, radius, radius * outer.tan());
        if r < cull.1 {
            cull = (c, r);
        }
        let proxy = cone_bounding_sphere(pos, dir, radius, g.cone_radius);
        return LightSpheres { cull, proxy };
    }
    g.volume = VOLUME_SPHERE;
    g.volume_scale = scales.sphere;
    LightSpheres {
        cull,
        proxy: sphere,
    }
}

impl LightLists {
    /// The frame's light lists as the passes read them: the visible-index
    /// buffer (the forward loop's lights first, then the volume lists), their
    /// ranges, and the cluster grid unless `culling` is `Volumes` (the GPU bins
    /// [`LightLists::locals`] into it: `cluster_gpu.rs`). The clusters' slices
    /// span `depth_near..depth_far` (the geometry's depth range).
    ///
    /// The forward loop runs a constant number of lights in the preprocessor and
    /// override modes: the visible count rounded up to a power of two, padded
    /// with a black light (appended to `gpu`). With cluster lists it is not
    /// used: bound 1.
    pub(crate) fn frame_lists(
        &mut self,
        culling: LightCulling,
        width: u32,
        height: u32,
        depth_near: f32,
        depth_far: f32,
    ) -> (FrameLists, Vec<u32>, Option<ClusterGrid>) {
        let visible_count = self.forward.len() as u32;
        let loop_count = match culling {
            LightCulling::Volumes => visible_count.max(1).next_power_of_two(),
            LightCulling::Clustered | LightCulling::None => 1,
        };
        let black = self.gpu.len() as u32;
        self.gpu.push(GpuLight {
            kind: KIND_DIRECTIONAL,
            direction: [0.0, 0.0, -1.0],
            ..bytemuck::Zeroable::zeroed()
        });
        let mut forward = self.forward.clone();
        forward.resize((loop_count as usize).max(forward.len()), black);
        let grid = frame_grid(culling, width, height, depth_near, depth_far);
        let mut visible: Vec<u32> = Vec::new();
        let mut range = |list: &[u32]| -> Range<u32> {
            let start = visible.len() as u32;
            visible.extend_from_slice(list);
            start..visible.len() as u32
        };
        let forward_range = range(&forward);
        debug_assert_eq!(forward_range.start, 0);
        let fl = FrameLists {
            fullscreen: range(&self.fullscreen),
            sphere_out: range(&self.sphere_out),
            sphere_in: range(&self.sphere_in),
            cone_out: range(&self.cone_out),
            cone_in: range(&self.cone_in),
            forward_lights: loop_count,
            clustered: grid.is_some(),
        };
        (fl, visible, grid)
    }
}

/// The cluster grid of a `width`×`height` frame whose slices span
/// `depth_near..depth_far`: 32-pixel tiles and 24 slices when clustered, one
/// cluster without culling, none with light volumes.
pub(crate) fn frame_grid(
    culling: LightCulling,
    width: u32,
    height: u32,
    depth_near: f32,
    depth_far: f32,
) -> Option<ClusterGrid> {
    let (tile, slices) = match culling {
        LightCulling::Volumes => return None,
        LightCulling::Clustered => (clusters::TILE_PX, clusters::SLICES),
        LightCulling::None => (0, 1),
    };
    Some(ClusterGrid::new(
        width, height, depth_near, depth_far, tile, slices,
    ))
}

/// The six view-space frustum planes `(n, d)` with `n·p + d >= 0` inside, for a
/// projection with depth 0..1 (Gribb-Hartmann).
pub(crate) fn frustum_planes(proj: &Mat4) -> [Vec4; 6] {
    let r = |i: usize| proj.row(i);
    let planes = [
        r(3) + r(0),
        r(3) - r(0),
        r(3) + r(1),
        r(3) - r(1),
        r(2),
        r(3) - r(2),
    ];
    planes.map(|p| p / p.truncate().length().max(1e-20))
}

/// Bounding sphere of a cone with apex `apex`, unit axis `axis`, length `h` and base
/// radius `rb`.
fn cone_bounding_sphere(apex: Vec3, axis: Vec3, h: f32, rb: f32) -> (Vec3, f32) {
    if rb <= h {
        let c = (h * h + rb * rb) / (2.0 * h);
        (apex + axis * c, c)
    } else {
        (apex + axis * h, rb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frustum_planes_contain_the_view_axis() {
        let proj = crate::scene::perspective_rh(1.0, 1.5, 0.1, 100.0);
        let planes = frustum_planes(&proj);
        let inside = Vec3::new(0.0, 0.0, -10.0);
        assert!(planes.iter().all(|p| p.truncate().dot(inside) + p.w > 0.0));
        let behind = Vec3::new(0.0, 0.0, 10.0);
        assert!(planes.iter().any(|p| p.truncate().dot(behind) + p.w < 0.0));
    }

    #[test]
    fn cone_sphere_contains_the_cone() {
        let (c, r) = cone_bounding_sphere(Vec3::ZERO, Vec3::Z, 2.0, 1.0);
        for p in [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, -1.0, 2.0),
        ] {
            assert!((p - c).length() <= r + 1e-5);
        }
    }
}
