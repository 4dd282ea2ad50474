//! Group 2 (per material: parameters, textures, sampler, feature bits) and group 3
//! (lighting parameters) of the geometry passes.

use super::geometry::{Geometry, MESH_FLAGS};
use crate::gpu::bindings;
use crate::gpu::context::GpuContext;
use crate::render::error::RenderError;
use crate::render::material::template::{feature_words, FEATURES_BINDING};
use crate::render::material::MaterialSet;
use crate::scene::Scene;
use std::collections::HashMap;
use wgpu::util::DeviceExt;

/// Group 2 (per material) and group 3 (lighting parameters) resources.
pub(crate) struct MaterialResources {
    /// One layout per surface shader.
    pub layouts: Vec<wgpu::BindGroupLayout>,
    /// One bind group per (material, mesh flags) drawn; see [`MaterialResources::group`].
    groups: HashMap<(usize, u64), wgpu::BindGroup>,
    pub params_layout: wgpu::BindGroupLayout,
    pub params_group: wgpu::BindGroup,
    /// GPU textures created (each image once per colour space).
    pub textures: usize,
}

/// The stages that run surface shaders: the geometry passes' fragments and
/// the visibility buffer's material resolve (`crate::render::visibility`).
const SURFACE_STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

/// A 2D texture of a material's group.
fn texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    let d2 = wgpu::TextureViewDimension::D2;
    bindings::texture_entry(binding, SURFACE_STAGES, sample_type, d2)
}

/// A uniform buffer of a material's group.
fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    bindings::uniform_entry(binding, SURFACE_STAGES)
}

impl MaterialResources {
    /// The bind group of a batch of `material` with feature bits `features`.
    pub fn group(&self, material: usize, features: u64) -> &wgpu::BindGroup {
        &self.groups[&(material, features & MESH_FLAGS)]
    }

    /// Checks the textures, makes one group-2 layout per surface shader, one
    /// group per (material, mesh flags) drawn, and group 3.
    pub fn upload(
        ctx: &GpuContext,
        scene: &Scene,
        set: &MaterialSet,
        geometry: &Geometry,
        mipmaps: bool,
        white: &wgpu::TextureView,
    ) -> Result<MaterialResources, RenderError> {
        let device = &ctx.device;
        check_textures(scene, device.limits().max_texture_dimension_2d)?;
        let layouts = surface_layouts(device, set);
        let sampler = material_sampler(device);
        let mut textures = super::textures::TextureCache::new(scene, mipmaps);
        let inputs = GroupInputs {
            set,
            layouts: &layouts,
            sampler: &sampler,
            white,
        };
        let mut groups = HashMap::new();
        for (mi, mesh_bits) in drawn_pairs(geometry) {
            let group = inputs.material_group(ctx, &mut textures, mi, mesh_bits)?;
            groups.insert((mi, mesh_bits), group);
        }
        let (params_layout, params_group) = lighting_params(device, set);
        Ok(MaterialResources {
            layouts,
            groups,
            params_layout,
            params_group,
            textures: textures.len(),
        })
    }
}

/// Every texture is 1..`max_dim` pixels wide and high, with 4 bytes a pixel.
fn check_textures(scene: &Scene, max_dim: u32) -> Result<(), RenderError> {
    let name = &scene.name;
    for t in &scene.textures {
        if t.width == 0 || t.height == 0 || t.width > max_dim || t.height > max_dim {
            return Err(RenderError::Invalid(format!(
                "{name}: texture `{}` is {}x{}; this device allows 1..{max_dim} px",
                t.name, t.width, t.height
            )));
        }
        if t.rgba8.len() != (t.width * t.height * 4) as usize {
            return Err(RenderError::Invalid(format!(
                "{name}: texture `{}` has {} bytes for {}x{} RGBA8",
                t.name,
                t.rgba8.len(),
                t.width,
                t.height
            )));
        }
    }
    Ok(())
}

/// One group-2 layout per surface shader: its parameters, textures and
/// samplers, and the feature bits.
fn surface_layouts(device: &wgpu::Device, set: &MaterialSet) -> Vec<wgpu::BindGroupLayout> {
    set.surfaces
        .iter()
        .map(|s| {
            let mut entries = Vec::new();
            if let Some(b) = s.shader.params_binding {
                entries.push(uniform_entry(b));
            }
            let filterable = wgpu::TextureSampleType::Float { filterable: true };
            for t in &s.shader.textures {
                entries.push(texture_entry(t.binding, filterable));
            }
            for sampler in &s.shader.samplers {
                let ty = wgpu::SamplerBindingType::Filtering;
                entries.push(bindings::sampler_entry(sampler.binding, SURFACE_STAGES, ty));
            }
            entries.push(uniform_entry(FEATURES_BINDING));
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(&format!("deferred group 2 (surface {})", s.name)),
                entries: &entries,
            })
        })
        .collect()
}

/// The one sampler of every material texture: linear, repeating.
fn material_sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("deferred material sampler"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    })
}

/// The (material, mesh flags) pairs drawn, sorted, each once: one bind group
/// each, as the branching mode reads the exact feature bits (material's and
/// mesh's) from it.
fn drawn_pairs(geometry: &Geometry) -> Vec<(usize, u64)> {
    let mut pairs: Vec<(usize, u64)> = geometry
        .batches
        .iter()
        .chain(geometry.blend_items.iter().map(|b| &b.batch))
        .map(|b| (b.material, b.features & MESH_FLAGS))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// What every material's group is made from.
struct GroupInputs<'a> {
    set: &'a MaterialSet,
    layouts: &'a [wgpu::BindGroupLayout],
    sampler: &'a wgpu::Sampler,
    /// Bound where a material has no texture.
    white: &'a wgpu::TextureView,
}

impl GroupInputs<'_> {
    /// The group of material `mi` drawn with `mesh_bits`: its parameters,
    /// textures (white where it has none), the sampler and the feature bits.
    fn material_group(
        &self,
        ctx: &GpuContext,
        textures: &mut super::textures::TextureCache<'_>,
        mi: usize,
        mesh_bits: u64,
    ) -> Result<wgpu::BindGroup, RenderError> {
        let device = &ctx.device;
        let m = &self.set.materials[mi];
        let s = &self.set.surfaces[m.surface];
        let label = format!("deferred material {} (mesh flags {mesh_bits:#x})", m.name);
        let mut slot_views = Vec::with_capacity(m.textures.len());
        for (slot, tex) in m.textures.iter().enumerate() {
            slot_views.push(match tex {
                Some(i) => textures.view(ctx, *i, s.shader.textures[slot].srgb)?,
                None => self.white.clone(),
            });
        }
        let params = (!m.surface_params.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} parameters")),
                contents: &m.surface_params,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        });
        let feature_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&format!("{label} feature bits")),
            contents: bytemuck::cast_slice(&feature_words(m.features | mesh_bits)),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut entries = Vec::new();
        if let (Some(b), Some(buf)) = (s.shader.params_binding, &params) {
            entries.push(wgpu::BindGroupEntry {
                binding: b,
                resource: buf.as_entire_binding(),
            });
        }
        for (t, v) in s.shader.textures.iter().zip(&slot_views) {
            entries.push(wgpu::BindGroupEntry {
                binding: t.binding,
                resource: wgpu::BindingResource::TextureView(v),
            });
        }
        for sampler_var in &s.shader.samplers {
            entries.push(wgpu::BindGroupEntry {
                binding: sampler_var.binding,
                resource: wgpu::BindingResource::Sampler(self.sampler),
            });
        }
        entries.push(wgpu::BindGroupEntry {
            binding: FEATURES_BINDING,
            resource: feature_buffer.as_entire_binding(),
        });
        let layout = &self.layouts[m.surface];
        Ok(ctx.scoped(&label, |device| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&label),
                layout,
                entries: &entries,
            })
        })?)
    }
}

/// Group 3: per lighting model with parameters, an array over all material
/// ids (entries of other models stay zero).
fn lighting_params(
    device: &wgpu::Device,
    set: &MaterialSet,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let mut p_entries = Vec::new();
    let mut p_buffers = Vec::new();
    for (k, l) in set.lightings.iter().enumerate() {
        if !l.takes_params() {
            continue;
        }
        let stride = l.params_stride().max(4);
        let mut bytes = vec![0u8; stride * set.materials.len().max(1)];
        for (i, m) in set.materials.iter().enumerate() {
            if m.lighting == k {
                bytes[i * stride..i * stride + m.lighting_params.len()]
                    .copy_from_slice(&m.lighting_params);
            }
        }
        // (the compute light pass runs the lighting shaders too)
        p_entries.push(bindings::storage_entry(
            k as u32,
            wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ));
        p_buffers.push((
            k as u32,
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("deferred lighting parameters ({})", l.name)),
                contents: &bytes,
                usage: wgpu::BufferUsages::STORAGE,
            }),
        ));
    }
    let params_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("deferred group 3 (lighting parameters)"),
        entries: &p_entries,
    });
    let params_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("deferred group 3 (lighting parameters)"),
        layout: &params_layout,
        entries: &p_buffers
            .iter()
            .map(|(b, buf)| wgpu::BindGroupEntry {
                binding: *b,
                resource: buf.as_entire_binding(),
            })
            .collect::<Vec<_>>(),
    });
    (params_layout, params_group)
}
