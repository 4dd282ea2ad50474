//! The lights of the clustered and unculled paths in world space, built when
//! the lights change (not per frame): the GPU light array as the shaders read
//! it but with world positions and directions (`light_view.wgsl` moves them
//! into view space each frame), the culling sphere of every point and spot
//! light, the global (directional) lights, the ambient sum, and the few lights
//! that may cast shadows (planned on the CPU per frame, as the volumes path
//! plans them).

use super::gpu_types::*;
use super::lights::{directional_light, local_radius, shape_volume, LightSpheres, VolumeScales};
use crate::scene::{Light, LightKind};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

/// `WorldLocal` of light_view.wgsl: a point or spot light's culling sphere in
/// world space and its index in the light array.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub(crate) struct GpuWorldLocal {
    pub center: [f32; 3],
    pub radius: f32,
    pub index: u32,
    pub _pad: [u32; 3],
}

/// A light that may get shadow maps.
#[derive(Debug, Clone, Copy)]
struct Caster {
    index: u32,
    /// World position and unit direction (as the shadow planner reads them).
    place: (Vec3, Vec3),
    /// The culling sphere (world space) of a point or spot light.
    cull: Option<(Vec3, f32)>,
}

/// The world-space lights of a renderer (see the module notes).
#[derive(Debug, Default)]
pub(crate) struct WorldLights {
    /// One per lit directional, point and spot light, then a black light.
    pub gpu: Vec<GpuLight>,
    pub locals: Vec<GpuWorldLocal>,
    pub globals: Vec<u32>,
    /// Sum of the ambient lights (colour × intensity).
    pub ambient: Vec3,
    /// Lights skipped because their intensity is zero, negative or not finite.
    pub dark: usize,
    casters: Vec<Caster>,
}

/// The shadow casters in view of one frame, as the shadow planner takes them.
pub(crate) struct FrameCasters {
    /// Their view-space GPU lights (the planner writes their layers here).
    pub gpu: Vec<GpuLight>,
    pub world: Vec<(Vec3, Vec3)>,
    indices: Vec<u32>,
}

impl WorldLights {
    /// Lists `lights` as the volumes path's classification would, in world
    /// space and without culling.
    pub fn new(lights: &[Light], scales: VolumeScales) -> WorldLights {
        let mut w = WorldLights::default();
        for l in lights {
            let color = l.color * l.intensity;
            if color.max_element() <= 0.0 || !color.is_finite() {
                w.dark += 1;
                continue;
            }
            let dir = l.direction.normalize_or(Vec3::NEG_Z);
            let mut g = directional_light(l, color, dir);
            let index = w.gpu.len() as u32;
            let cull = match l.kind {
                LightKind::Ambient => {
                    w.ambient += color;
                    continue;
                }
                LightKind::Directional => {
                    w.globals.push(index);
                    None
                }
                LightKind::Point | LightKind::Spot { .. } => {
                    let Some(radius) = local_radius(l) else {
                        continue;
                    };
                    g.position = l.position.into();
                    g.radius = radius;
                    let LightSpheres { cull, .. } =
                        shape_volume(l, &mut g, l.position, dir, scales);
                    w.locals.push(GpuWorldLocal {
                        center: cull.0.into(),
                        radius: cull.1,
                        index,
                        _pad: [0; 3],
                    });
                    Some(cull)
                }
            };
            if super::shadows::layers_of(g.kind) > 0 && g.casts_shadows != 0 {
                w.casters.push(Caster {
                    index,
                    place: (l.position, l.direction.normalize_or(Vec3::NEG_Y)),
                    cull,
                });
            }
            w.gpu.push(g);
        }
        w.gpu.push(GpuLight {
            kind: KIND_DIRECTIONAL,
            direction: [0.0, 0.0, -1.0],
            ..Zeroable::zeroed()
        });
        w
    }

    /// The black light's index (the forward loop's padding).
    pub fn black(&self) -> u32 {
        self.gpu.len() as u32 - 1
    }

    /// The shadow casters whose culling sphere is inside the frustum `planes`
    /// (view space) of `view`, moved into view space.
    pub fn casters_in_view(&self, view: &Mat4, planes: &[Vec4; 6]) -> FrameCasters {
        let mut out = FrameCasters {
            gpu: Vec::new(),
            world: Vec::new(),
            indices: Vec::new(),
        };
        for c in &self.casters {
            if let Some((center, radius)) = c.cull {
                let center = view.transform_point3(center);
                if planes
                    .iter()
                    .any(|p| p.truncate().dot(center) + p.w < -radius)
                {
                    continue;
                }
            }
            let mut g = self.gpu[c.index as usize];
            if g.kind != KIND_DIRECTIONAL {
                g.position = view.transform_point3(Vec3::from(g.position)).into();
            }
            g.direction = view
                .transform_vector3(Vec3::from(g.direction))
                .normalize_or(Vec3::NEG_Z)
                .into();
            out.gpu.push(g);
            out.world.push(c.place);
            out.indices.push(c.index);
        }
        out
    }

    /// Takes the shadow layers the planner gave `casters` (none for the
    /// casters out of view). Returns the indices of the lights that changed.
    pub fn apply_shadows(&mut self, casters: &FrameCasters) -> Vec<u32> {
        let mut changed = Vec::new();
        let mut planned = casters.indices.iter().zip(&casters.gpu).peekable();
        for c in &self.casters {
            let next = planned.peek().map(|&(i, g)| (*i, *g));
            let (first, count, filter) = match next {
                Some((i, g)) if i == c.index => {
                    planned.next();
                    (g.shadow_first, g.shadow_count, g.shadow_filter)
                }
                _ => (0, 0, 0),
            };
            let l = &mut self.gpu[c.index as usize];
            if (l.shadow_first, l.shadow_count, l.shadow_filter) != (first, count, filter) {
                (l.shadow_first, l.shadow_count, l.shadow_filter) = (first, count, filter);
                changed.push(c.index);
            }
        }
        changed
    }
}

#[cfg(test)]
impl WorldLights {
    /// `lights` lights (white points), of which `spheres` are binned with the
    /// given culling spheres (in world space; the lights at their centres);
    /// `globals` listed first.
    pub fn for_tests(
        lights: u32,
        globals: &[u32],
        spheres: &[super::clusters::LocalLight],
    ) -> WorldLights {
        let point = GpuLight {
            kind: KIND_POINT,
            color: [1.0; 3],
            ..Zeroable::zeroed()
        };
        let mut gpu = vec![point; lights as usize + 1];
        for l in spheres {
            gpu[l.index as usize].position = l.center.into();
        }
        WorldLights {
            gpu,
            locals: spheres
                .iter()
                .map(|l| GpuWorldLocal {
                    center: l.center.into(),
                    radius: l.radius,
                    index: l.index,
                    _pad: [0; 3],
                })
                .collect(),
            globals: globals.to_vec(),
            ..Default::default()
        }
    }
}
