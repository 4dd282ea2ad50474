//! The renderer's GPU-side structs (`#[repr(C)]`, laid out as their WGSL twins in
//! `shaders/engine.wgsl`) and their constants.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

/// One vertex of the scene's single vertex buffer (72 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv0: [f32; 2],
    pub uv1: [f32; 2],
    /// xyz + handedness; all zero where the mesh has no tangents.
    pub tangent: [f32; 4],
    /// Linear vertex colour; 1 where the mesh has none.
    pub color: [f32; 4],
}

/// `FxFrame`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct GpuFrame {
    pub view: [f32; 16],
    pub proj: [f32; 16],
    pub inv_proj: [f32; 16],
    pub proj_unjittered: [f32; 16],
    pub reproject: [f32; 16],
    pub viewport: [f32; 4],
    pub background: [f32; 4],
    pub ambient: [f32; 4],
    pub near: f32,
    pub far: f32,
    pub light_count: u32,
    /// Global lights at the start of the cluster light list.
    pub global_lights: u32,
    /// tiles x, tiles y, slices, tile size in pixels (0: no clustered lists).
    pub cluster: [u32; 4],
    /// slices / ln(far / near), near of the slices, 0, 0.
    pub cluster_z: [f32; 4],
    pub fog: super::fog::GpuFog,
}

/// `FxMaterialInfo`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct GpuMaterialInfo {
    pub model: u32,
    pub alpha_cutoff: f32,
    pub _pad: [u32; 2],
}

/// `FxInstance`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct GpuInstance {
    pub model: [f32; 16],
    pub normal: [f32; 16],
    pub material: u32,
    pub _pad: [u32; 3],
}

/// `FxLight` (view space).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub(crate) struct GpuLight {
    pub position: [f32; 3],
    pub radius: f32,
    pub color: [f32; 3],
    pub kind: u32,
    pub direction: [f32; 3],
    pub volume_scale: f32,
    pub atten: [f32; 3],
    pub cos_outer: f32,
    pub cos_inner: f32,
    pub cone_radius: f32,
    pub volume: u32,
    /// KHR_lights_punctual range (0: none).
    pub range: f32,
    /// First shadow-map layer (`shadows.rs`); meaningful when `shadow_count > 0`.
    pub shadow_first: u32,
    /// Shadow-map layers of the light: 0 (no shadows; so a zeroed light has
    /// none), 1 spot, 4 directional cascades, 6 point cube faces.
    pub shadow_count: u32,
    /// 1 hard, 2 PCF (`ShadowMode::filter_id`).
    pub shadow_filter: u32,
    /// 1: the light may get a shadow map ([`crate::scene::Light::casts_shadows`];
    /// read on the CPU only).
    pub casts_shadows: u32,
}

pub(crate) const KIND_DIRECTIONAL: u32 = 1;
pub(crate) const KIND_POINT: u32 = 2;
pub(crate) const KIND_SPOT: u32 = 3;

pub(crate) const VOLUME_FULLSCREEN: u32 = 0;
pub(crate) const VOLUME_SPHERE: u32 = 1;
pub(crate) const VOLUME_CONE: u32 = 2;

pub(crate) fn mat_array(m: Mat4) -> [f32; 16] {
    m.to_cols_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn struct_sizes_match_wgsl() {
        assert_eq!(std::mem::size_of::<GpuFrame>(), 480);
        assert_eq!(std::mem::size_of::<GpuMaterialInfo>(), 16);
        assert_eq!(std::mem::size_of::<GpuInstance>(), 144);
        assert_eq!(std::mem::size_of::<GpuLight>(), 96);
        assert_eq!(std::mem::size_of::<Vertex>(), 72);
    }
}
