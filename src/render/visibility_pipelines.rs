//! The visibility buffer's pipelines (`visibility.rs`): the raster half's,
//! one per face culling, and each material variant's resolve dispatch, with
//! the resolve's group-1 layout.

use super::gpu_types::Vertex;
use super::pass_states::{depth, target};
use super::pipelines::{create, Layouts};
use super::upload::Cull;
use super::visibility_shader::{classify_module, raster_module};
use super::wgsl_check::check;
use crate::gpu::bindings;
use crate::gpu::context::GpuContext;

/// The id target: instance slot, triangle within the draw.
pub(crate) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

/// Group 1 of the resolve: the ids, vertices, indices, slots, the dispatch's
/// uniform (dynamic offset), the four G-buffer outputs, and the
/// classification's tile lists and counts.
pub(crate) fn resolve_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let cs = wgpu::ShaderStages::COMPUTE;
    let store = |binding, format| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: cs,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("visibility resolve group 1 (ids, geometry, G-buffer outputs)"),
        entries: &[
            bindings::texture_entry(
                2,
                cs,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2,
            ),
            bindings::storage_entry(3, cs),
            bindings::storage_entry(4, cs),
            bindings::storage_entry(5, cs),
            wgpu::BindGroupLayoutEntry {
                binding: 6,
                visibility: cs,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(16),
                },
                count: None,
            },
            store(7, wgpu::TextureFormat::Rgba8Unorm),
            store(8, wgpu::TextureFormat::Rgb10a2Unorm),
            store(9, wgpu::TextureFormat::Rgba8Unorm),
            store(10, wgpu::TextureFormat::Rgba16Float),
            bindings::storage_entry(11, cs),
            bindings::storage_entry(12, cs),
        ],
    })
}

/// The raster half's pipeline for batches culled as `cull`.
pub(crate) fn raster_pipeline(
    ctx: &GpuContext,
    layouts: &Layouts,
    cull: Cull,
) -> Result<wgpu::RenderPipeline, String> {
    let label = format!("visibility raster pipeline {cull:?}");
    check(&label, raster_module())?;
    let module = ctx
        .scoped(&label, |device| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(&label),
                source: wgpu::ShaderSource::Wgsl(raster_module().into()),
            })
        })
        .map_err(|e| e.to_string())?;
    let attrs = wgpu::vertex_attr_array![0 => Float32x3];
    let buffers = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attrs,
    })];
    create(
        ctx,
        &label,
        &module,
        ("fx_vs_visibility", "fx_fs_visibility"),
        &buffers,
        &[target(ID_FORMAT)],
        depth(true, wgpu::CompareFunction::Less),
        cull.primitive(),
        &[Some(&layouts.g0)],
        &[],
    )
}

/// A material variant's resolve pipeline, from its module `text`, over
/// `groups` (group 0, the resolve's group 1, the surface's group 2, the
/// lighting parameters).
pub(crate) fn resolve_pipeline(
    ctx: &GpuContext,
    label: &str,
    groups: [&wgpu::BindGroupLayout; 4],
    text: &str,
) -> Result<wgpu::ComputePipeline, String> {
    ctx.scoped(label, |device| {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(text.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &groups.map(Some),
            immediate_size: 0,
        });
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("fx_cs_visibility_resolve"),
            compilation_options: Default::default(),
            cache: ctx.pipeline_cache.as_ref(),
        })
    })
    .map_err(|e| e.to_string())
}

/// The tile classification's group 0: the ids and slots (read), the lists'
/// counts, tiles and indirect arguments (written).
pub(crate) fn classify_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let cs = wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("visibility classification group 0 (ids, slots, tile lists)"),
        entries: &[
            bindings::texture_entry(
                0,
                cs,
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D2,
            ),
            bindings::storage_entry(1, cs),
            bindings::storage_rw_entry(2, cs),
            bindings::storage_rw_entry(3, cs),
            bindings::storage_rw_entry(4, cs),
        ],
    })
}

/// The classification's two pipelines (the tiles, then the indirect
/// arguments) for `groups` resolve dispatches.
pub(crate) fn classify_pipelines(
    ctx: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    groups: usize,
) -> Result<[wgpu::ComputePipeline; 2], String> {
    let label = "visibility tile classification";
    let text = classify_module(groups);
    check(label, &text)?;
    ctx.scoped(label, |device| {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(text.as_str().into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(layout)],
            immediate_size: 0,
        });
        ["fx_cs_visibility_classify", "fx_cs_visibility_args"].map(|entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&format!("{label} ({entry})")),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: ctx.pipeline_cache.as_ref(),
            })
        })
    })
    .map_err(|e| e.to_string())
}
