//! What each geometry pass and light-module pipeline renders: its fragment
//! entry point, colour targets (and their blending) and depth test; for the
//! light pipelines also the vertex stage, vertex buffers and culling.

use super::targets::*;
use super::upload::Cull;

/// A geometry pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum GeoPass {
    GBuffer,
    Prepass,
    LppFinal,
    Forward,
    ForwardBlend,
}

/// A light-module pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum LightPipe {
    Clustered,
    Fullscreen,
    VolumeFront,
    VolumeBack,
    Compose,
    /// The environment behind the geometry (light pre-pass and forward).
    Background,
    AuxA,
    AuxB,
}

/// The stages, vertex buffers, targets and depth test of a light-module pipeline.
pub(super) struct LightStages<'a> {
    pub vs: &'static str,
    pub fs: &'static str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub targets: Vec<Option<wgpu::ColorTargetState>>,
    pub depth_state: Option<wgpu::DepthStencilState>,
    pub primitive: wgpu::PrimitiveState,
}

pub(crate) fn target(format: wgpu::TextureFormat) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState {
        format,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })
}

fn additive(format: wgpu::TextureFormat) -> Option<wgpu::ColorTargetState> {
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    Some(wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState {
            color: add,
            alpha: add,
        }),
        write_mask: wgpu::ColorWrites::ALL,
    })
}

pub(crate) fn depth(
    write: bool,
    compare: wgpu::CompareFunction,
) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    })
}

/// The fragment entry point, colour targets and depth test of geometry pass
/// `pass`.
pub(super) fn geo_outputs(
    pass: GeoPass,
) -> (
    &'static str,
    Vec<Option<wgpu::ColorTargetState>>,
    Option<wgpu::DepthStencilState>,
) {
    match pass {
        GeoPass::GBuffer => (
            "fx_fs_gbuffer",
            vec![
                target(ALBEDO_FORMAT),
                target(NORMAL_FORMAT),
                target(SPECULAR_FORMAT),
                target(LIGHT_FORMAT),
            ],
            depth(true, wgpu::CompareFunction::Less),
        ),
        GeoPass::Prepass => (
            "fx_fs_prepass",
            vec![
                Some(wgpu::ColorTargetState {
                    format: ALBEDO_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALPHA,
                }),
                target(NORMAL_FORMAT),
                target(SPECULAR_FORMAT),
            ],
            depth(true, wgpu::CompareFunction::Less),
        ),
        GeoPass::LppFinal => (
            "fx_fs_lpp_final",
            vec![target(SCENE_FORMAT), target(ALBEDO_FORMAT)],
            depth(false, wgpu::CompareFunction::LessEqual),
        ),
        GeoPass::Forward => (
            "fx_fs_forward",
            vec![
                target(SCENE_FORMAT),
                target(ALBEDO_FORMAT),
                target(NORMAL_FORMAT),
                target(SPECULAR_FORMAT),
            ],
            depth(true, wgpu::CompareFunction::Less),
        ),
        GeoPass::ForwardBlend => (
            "fx_fs_forward_blend",
            vec![Some(wgpu::ColorTargetState {
                format: SCENE_FORMAT,
                // colour: over; alpha: coverage accumulates (a + (1 - a)
                // dst), so a transparent background keeps the glass's
                blend: Some(wgpu::BlendState {
                    color: wgpu::BlendState::ALPHA_BLENDING.color,
                    alpha: wgpu::BlendComponent {
                        src_factor: wgpu::BlendFactor::One,
                        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                        operation: wgpu::BlendOperation::Add,
                    },
                }),
                write_mask: wgpu::ColorWrites::ALL,
            })],
            depth(false, wgpu::CompareFunction::Less),
        ),
    }
}

/// The stages of light-module pipeline `which` (`volume_vb`: the light
/// volumes' vertex buffer; `aux_formats`: the AUX images the resolve writes).
pub(super) fn light_stages<'a>(
    which: LightPipe,
    aux_formats: &[(String, wgpu::TextureFormat)],
    volume_vb: &'a [Option<wgpu::VertexBufferLayout<'a>>],
) -> LightStages<'a> {
    let aux = |i: usize| target(aux_formats[i].1);
    let lights_targets = vec![additive(LIGHT_FORMAT), additive(LIGHT_FORMAT)];
    use wgpu::CompareFunction as C;
    // A full-screen triangle (no vertex buffer, no culling) and a light
    // volume (its vertex buffer, faces culled as `primitive` says).
    let fullscreen = |vs, fs, targets, depth_state| LightStages {
        vs,
        fs,
        buffers: &[],
        targets,
        depth_state,
        primitive: wgpu::PrimitiveState::default(),
    };
    let volume = |depth_state, primitive| LightStages {
        vs: "fx_vs_volume",
        fs: "fx_fs_light",
        buffers: volume_vb,
        targets: lights_targets.clone(),
        depth_state,
        primitive,
    };
    let always = depth(false, C::Always);
    let scene = || vec![target(SCENE_FORMAT)];
    match which {
        LightPipe::Clustered => fullscreen(
            "fx_vs_fullscreen",
            "fx_fs_light_clustered",
            lights_targets.clone(),
            always,
        ),
        LightPipe::Fullscreen => fullscreen(
            "fx_vs_light_fullscreen",
            "fx_fs_light",
            lights_targets.clone(),
            always,
        ),
        LightPipe::VolumeFront => volume(depth(false, C::Less), Cull::BackCcw.primitive()),
        LightPipe::VolumeBack => volume(
            depth(false, C::GreaterEqual),
            wgpu::PrimitiveState {
                cull_mode: Some(wgpu::Face::Front),
                ..Default::default()
            },
        ),
        LightPipe::Compose => fullscreen("fx_vs_fullscreen", "fx_fs_compose", scene(), None),
        LightPipe::Background => fullscreen("fx_vs_fullscreen", "fx_fs_background", scene(), None),
        LightPipe::AuxA => fullscreen(
            "fx_vs_fullscreen",
            "fx_fs_aux_a",
            vec![aux(0), aux(1), aux(2), aux(6)],
            None,
        ),
        LightPipe::AuxB => fullscreen(
            "fx_vs_fullscreen",
            "fx_fs_aux_b",
            vec![aux(3), aux(4), aux(5)],
            None,
        ),
    }
}
