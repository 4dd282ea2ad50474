//! Compute pipelines for several entry points of one WGSL module under one
//! explicit group-0 layout: how the renderer's multi-pass compute stages (the
//! light view, the light clusters) are built.

/// One compute pipeline per entry point of `entries` in WGSL `source`, all
/// with the pipeline layout of `layout` as group 0, labelled `label` and
/// `label entry`, through the device's pipeline `cache` where it has one.
pub fn compute_pipelines<const N: usize>(
    device: &wgpu::Device,
    cache: Option<&wgpu::PipelineCache>,
    label: &str,
    source: &str,
    layout: &wgpu::BindGroupLayout,
    entries: [&str; N],
) -> [wgpu::ComputePipeline; N] {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    entries.map(|entry| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&format!("{label} {entry}")),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache,
        })
    })
}
