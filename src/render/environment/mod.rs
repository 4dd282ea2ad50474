//! Image-based lighting: the renderer's side of a scene's
//! [`Environment`](crate::scene::Environment).
//!
//! - `prefilter.rs` (+ `prefilter.wgsl`): the map made into a GGX-prefiltered
//!   specular cube map, a diffuse irradiance cube map and the split-sum DFG table,
//!   on the GPU, once per map: the result is cached by (map content, face size),
//!   so a sequence or a renderer given the same map again prefilters once.
//! - `bright.rs`: the map's brightest cells (a sun, lamps) taken out of the
//!   specular levels from 1 on and shaded exactly per pixel.
//! - `dfg.rs`: the split-sum table and, beside it, the lobe model's taps
//!   (`lobe.rs`, fitted offline into `lobe_table.rs` by
//!   `examples/ibl_lobe_fit.rs`); `small_cube.rs`: the map as a 16² cube on
//!   the CPU for the exact convolutions; the renderer's methods are in `../renderer_environment.rs`.
//! - this file: [`EnvironmentLighting`], the state a [`super::Renderer`] keeps
//!   (the current maps, the cache, the background), its group-0 bindings 11–15
//!   and its per-frame uniform.
//! - `shaders/render/environment.wgsl`: the shading side, in every
//!   generated module: the lookups, the default environment term (split sum with
//!   Fdez-Agüera's multiple-scattering compensation, specular occlusion) and the
//!   background.

pub mod bright;
mod dfg;
mod levels;
mod lobe;
mod lobe_table;
mod prefilter;
mod small_cube;
mod spread;

pub use levels::{level_roughness, position_of, roughness_at, LEVEL_ROUGHNESS};
pub use prefilter::{
    face_size, specular_levels, CONVOLVED_ROUGHNESS, CONVOLVED_SIDE, DFG_SAMPLES, DFG_SIZE,
    IRRADIANCE_FACE, MAX_FACE, SPECULAR_SAMPLES,
};

use crate::gpu::bindings::{sampler_entry, texture_entry, uniform_entry};
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::transfer::texture_2d;
use crate::scene::{Background, Environment, EnvironmentMap};
use bright::BrightCell;
use glam::{Mat3, Mat4, Vec3};
use prefilter::{PrefilterPipelines, Prefiltered, FORMAT};
use std::collections::HashMap;
use std::sync::Arc;

/// Group-0 bindings of the environment (after the shadow maps' 8–10).
const BINDING_SPECULAR: u32 = 11;
const BINDING_IRRADIANCE: u32 = 12;
const BINDING_DFG: u32 = 13;
const BINDING_SAMPLER: u32 = 14;
const BINDING_UNIFORM: u32 = 15;

pub(crate) use dfg::Dfg;
pub use lobe::{lobe_taps, LOBE_MU, LOBE_ROUGHNESS, LOBE_TABLE, LOBE_TAPS};

/// `FxEnvironment` of environment.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuEnvironment {
    /// View-space directions → the map's frame (columns, padded).
    map_from_view: [[f32; 4]; 3],
    /// intensity, last specular level, background level, background fog
    /// transmittance.
    params: [f32; 4],
    /// rgb: the fog colour the background is mixed towards.
    fog_color: [f32; 4],
    /// x: an environment lights the scene; y: background 0 colour, 1
    /// environment, 2 transparent; z: bright cells.
    flags: [u32; 4],
    /// [`bright::lobe_norms`].
    bright_norm: [[f32; 4]; 4],
    /// The map's bright cells ([`bright::split`]), the first `flags.z`.
    bright: [BrightCell; bright::MAX_CELLS],
}

/// The environment a renderer lights with, and its cache.
pub(crate) struct EnvironmentLighting {
    uniform: wgpu::Buffer,
    sampler: wgpu::Sampler,
    dummy_cube: wgpu::TextureView,
    dummy_dfg: wgpu::TextureView,
    pipes: Option<PrefilterPipelines>,
    dfg: Option<Dfg>,
    cache: HashMap<(u64, u32), Arc<Prefiltered>>,
    current: Option<(Arc<Prefiltered>, f32, f32)>,
    pub background: Background,
    /// Milliseconds the last [`EnvironmentLighting::set`] spent prefiltering (0
    /// when the cache had the map).
    pub last_prefilter_ms: f64,
    /// Maps prefiltered so far (cache misses).
    pub prefiltered: usize,
}

impl EnvironmentLighting {
    pub fn new(ctx: &GpuContext, background: Vec3) -> Result<EnvironmentLighting, GpuError> {
        ctx.scoped("environment lighting", |device| {
            let dummy = |label: &str, layers: u32, dimension| {
                device
                    .create_texture(&wgpu::TextureDescriptor {
                        label: Some(label),
                        size: wgpu::Extent3d {
                            width: 1,
                            height: 1,
                            depth_or_array_layers: layers,
                        },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format: FORMAT,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING,
                        view_formats: &[],
                    })
                    .create_view(&wgpu::TextureViewDescriptor {
                        label: Some(label),
                        dimension: Some(dimension),
                        ..Default::default()
                    })
            };
            EnvironmentLighting {
                uniform: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("environment uniforms"),
                    size: std::mem::size_of::<GpuEnvironment>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("environment sampler"),
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    mipmap_filter: wgpu::MipmapFilterMode::Linear,
                    ..Default::default()
                }),
                dummy_cube: dummy(
                    "environment placeholder cube (no environment)",
                    6,
                    wgpu::TextureViewDimension::Cube,
                ),
                dummy_dfg: dummy(
                    "environment placeholder DFG table (no environment)",
                    dfg::DFG_LAYERS,
                    wgpu::TextureViewDimension::D2Array,
                ),
                pipes: None,
                dfg: None,
                cache: HashMap::new(),
                current: None,
                background: Background::Color(background),
                last_prefilter_ms: 0.0,
                prefiltered: 0,
            }
        })
    }

    /// Lights with `env` (its map already loaded as `map`), prefiltering it
    /// unless the cache holds it; `None` turns environment lighting off. Group 0
    /// must be rebuilt afterwards.
    pub fn set(
        &mut self,
        ctx: &GpuContext,
        env: Option<(&Environment, &EnvironmentMap)>,
    ) -> Result<(), GpuError> {
        self.last_prefilter_ms = 0.0;
        let Some((env, map)) = env else {
            self.current = None;
            return Ok(());
        };
        if self.pipes.is_none() {
            self.pipes = Some(PrefilterPipelines::new(ctx)?);
        }
        let pipes = self.pipes.as_ref().expect("created above");
        if self.dfg.is_none() {
            self.dfg = Some(dfg::dfg_table(ctx, pipes)?);
        }
        let key = (map.key, face_size(map.map.width));
        let maps = match self.cache.get(&key) {
            Some(p) => {
                log::debug!("{}: prefiltered environment from the cache", map.name);
                p.clone()
            }
            None => {
                let p = Arc::new(prefilter::prefilter(ctx, pipes, map)?);
                self.last_prefilter_ms = p.ms;
                self.prefiltered += 1;
                self.cache.insert(key, p.clone());
                p
            }
        };
        self.current = Some((maps, env.intensity, env.rotation));
        Ok(())
    }

    /// Whether an environment lights the scene.
    pub fn is_on(&self) -> bool {
        self.current.is_some()
    }

    /// Whether the background is drawn from the environment (a pass of its own
    /// in the light pre-pass and forward techniques).
    pub fn background_pass(&self) -> bool {
        self.is_on() && matches!(self.background, Background::Environment { .. })
    }

    /// The clear colour of the scene image (alpha 0 for a transparent
    /// background), given the frame's (fogged) background colour.
    pub fn clear_color(&self, background: Vec3) -> glam::Vec4 {
        match self.background {
            Background::Transparent => glam::Vec4::ZERO,
            _ => background.extend(1.0),
        }
    }

    /// Writes the frame's uniform: the view's rotation into the map's frame, the
    /// intensity, the background (fogged with `fog` = (colour, transmittance at
    /// the far plane)).
    pub fn write_frame(&self, ctx: &GpuContext, view: &Mat4, fog: (Vec3, f32)) {
        let (intensity, rotation, levels) = match &self.current {
            Some((p, i, r)) => (*i, *r, p.levels),
            None => (0.0, 0.0, 1),
        };
        // view → world is the transpose of the view's rotation; world → map
        // undoes the environment's rotation about +Y
        let world_from_view = Mat3::from_mat4(*view).transpose();
        let m = Mat3::from_rotation_y(-rotation.to_radians()) * world_from_view;
        let col = |v: Vec3| [v.x, v.y, v.z, 0.0];
        let max_lod = (levels - 1) as f32;
        let (mode, blur) = match self.background {
            Background::Color(_) => (0, 0.0),
            Background::Environment { blur } => (if self.is_on() { 1 } else { 0 }, blur),
            Background::Transparent => (2, 0.0),
        };
        let mut bright = [BrightCell::default(); bright::MAX_CELLS];
        let cells = match &self.current {
            Some((p, _, _)) => &p.bright[..p.bright.len().min(bright::MAX_CELLS)],
            None => &[][..],
        };
        bright[..cells.len()].copy_from_slice(cells);
        let z = bright::lobe_norms();
        let g = GpuEnvironment {
            map_from_view: [col(m.x_axis), col(m.y_axis), col(m.z_axis)],
            params: [intensity, max_lod, position_of(blur) * max_lod, fog.1],
            fog_color: fog.0.extend(0.0).into(),
            flags: [u32::from(self.is_on()), mode, cells.len() as u32, 0],
            bright_norm: std::array::from_fn(|i| std::array::from_fn(|j| z[4 * i + j])),
            bright,
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&g));
    }

    /// The layout entries of bindings 11–15 in group 0.
    pub fn g0_layout_entries() -> [wgpu::BindGroupLayoutEntry; 5] {
        // (the compute light pass reads them too)
        let fragment = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let filterable = wgpu::TextureSampleType::Float { filterable: true };
        let texture = |binding, dimension| texture_entry(binding, fragment, filterable, dimension);
        [
            texture(BINDING_SPECULAR, wgpu::TextureViewDimension::Cube),
            texture(BINDING_IRRADIANCE, wgpu::TextureViewDimension::Cube),
            texture(BINDING_DFG, wgpu::TextureViewDimension::D2Array),
            sampler_entry(
                BINDING_SAMPLER,
                fragment,
                wgpu::SamplerBindingType::Filtering,
            ),
            uniform_entry(BINDING_UNIFORM, fragment),
        ]
    }

    /// The entries of bindings 11–15 (placeholders without an environment).
    pub fn g0_entries(&self) -> [wgpu::BindGroupEntry<'_>; 5] {
        let (specular, irradiance, dfg) = match (&self.current, &self.dfg) {
            (Some((p, _, _)), Some(d)) => (&p.specular_view, &p.irradiance_view, &d.view),
            _ => (&self.dummy_cube, &self.dummy_cube, &self.dummy_dfg),
        };
        let view = |binding, v| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        };
        [
            view(BINDING_SPECULAR, specular),
            view(BINDING_IRRADIANCE, irradiance),
            view(BINDING_DFG, dfg),
            wgpu::BindGroupEntry {
                binding: BINDING_SAMPLER,
                resource: wgpu::BindingResource::Sampler(&self.sampler),
            },
            wgpu::BindGroupEntry {
                binding: BINDING_UNIFORM,
                resource: self.uniform.as_entire_binding(),
            },
        ]
    }

    /// Reads back level `level` of face `face` of the specular map (`Some(k)`:
    /// `k`), or of the irradiance map (`None`), or the DFG table (`face` 6):
    /// RGBA f32 rows, and the side. For tests and inspection.
    pub fn read(
        &self,
        ctx: &GpuContext,
        map: EnvironmentTexture,
    ) -> Result<(u32, Vec<f32>), GpuError> {
        let missing = || GpuError::Validation {
            what: "environment readback".into(),
            message: "no environment is set".into(),
        };
        let (p, dfg) = match (&self.current, &self.dfg) {
            (Some((p, _, _)), Some(d)) => (p, d),
            _ => return Err(missing()),
        };
        let (texture, level, layer) = match map {
            EnvironmentTexture::Specular { level, face } => (&p.specular, level, face),
            EnvironmentTexture::Irradiance { face } => (&p.irradiance, 0, face),
            EnvironmentTexture::Dfg => (&dfg.texture, 0, 0),
        };
        let side = (texture.width() >> level).max(1);
        if level >= texture.mip_level_count() || layer >= texture.depth_or_array_layers() {
            return Err(GpuError::Validation {
                what: "environment readback".into(),
                message: format!("no level {level} / face {layer}"),
            });
        }
        let copy = ctx.scoped("environment readback", |device| {
            let usage = wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC;
            let label = "environment readback copy";
            let copy = device.create_texture(&texture_2d(label, (side, side), FORMAT, usage, &[]));
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("environment readback"),
            });
            encoder.copy_texture_to_texture(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: level,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: layer,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                copy.as_image_copy(),
                wgpu::Extent3d {
                    width: side,
                    height: side,
                    depth_or_array_layers: 1,
                },
            );
            ctx.queue.submit([encoder.finish()]);
            copy
        })?;
        let bytes = ctx.read_texture(&copy)?;
        Ok((
            side,
            bytes
                .chunks_exact(2)
                .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
                .collect(),
        ))
    }

    /// (levels, side) of the current specular map.
    pub fn specular_shape(&self) -> Option<(u32, u32)> {
        self.current.as_ref().map(|(p, _, _)| (p.levels, p.size))
    }
}

/// Which prefiltered texture [`EnvironmentLighting::read`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnvironmentTexture {
    /// Level `level` (roughness `level / (levels − 1)`) of cube face `face`
    /// (+X, −X, +Y, −Y, +Z, −Z).
    Specular { level: u32, face: u32 },
    /// Face `face` of the irradiance map (irradiance / π).
    Irradiance { face: u32 },
    /// The DFG table: x = n·v, y = roughness (texel centres), rg = A, B.
    Dfg,
}
