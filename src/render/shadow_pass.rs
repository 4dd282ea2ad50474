//! Shadow maps, the GPU side: the one `Depth32Float` array texture that holds
//! every layer, the comparison sampler and layer buffer the shaders read (group 0,
//! bindings 8–10), and the depth-only pass that renders each planned layer
//! (`shadows.rs` plans them) at the start of a frame.
//!
//! The depth pass draws positions only, with the instance's model matrix from
//! the instance buffer and a slope-scaled depth bias; no surface shader runs, so
//! MASK materials cast as if opaque, and transparent (BLEND) ones cast nothing.
//! Faces are not culled: open meshes (planes, leaves) cast from both sides.

use super::error::RenderError;
use super::gpu_types::{GpuLight, Vertex};
use super::options::RendererOptions;
use super::shadow_cache::{CasterChange, ShadowCache};
use super::shadows::{GpuShadowLayer, ShadowFrame, ShadowMode, MAX_SHADOW_SIZE, MIN_SHADOW_SIZE};
use super::upload::Geometry;
use crate::gpu::bindings::{sampler_entry, storage_entry, texture_entry};
use crate::gpu::context::{GpuContext, GpuTimer};

pub(crate) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Bindings of group 0 (5–7 are taken by the clustered light lists).
pub(crate) const BINDING_MAPS: u32 = 8;
pub(crate) const BINDING_SAMPLER: u32 = 9;
pub(crate) const BINDING_LAYERS: u32 = 10;
/// Stride of the per-layer matrices in the pass uniform buffer (the dynamic
/// offset alignment wgpu guarantees).
const PASS_STRIDE: u64 = 256;
/// Slope-scaled depth bias of the depth pass: the receiver's depth error grows
/// with its slope to the light; the constant part covers the rest (in units of
/// the depth format's precision at the primitive's depth).
const BIAS: wgpu::DepthBiasState = wgpu::DepthBiasState {
    constant: 2,
    slope_scale: 2.0,
    clamp: 0.0,
};
const SHADER: &str = concat!(
    include_str!("../../shaders/render/shadow_depth.wgsl"),
    include_str!("../../shaders/render/instance.wgsl")
);

/// The group 0 layout entries of the shadow lookups.
pub(crate) fn g0_layout_entries() -> [wgpu::BindGroupLayoutEntry; 3] {
    // (the compute light pass reads them too)
    let fragment = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    [
        texture_entry(
            BINDING_MAPS,
            fragment,
            wgpu::TextureSampleType::Depth,
            wgpu::TextureViewDimension::D2Array,
        ),
        sampler_entry(
            BINDING_SAMPLER,
            fragment,
            wgpu::SamplerBindingType::Comparison,
        ),
        storage_entry(BINDING_LAYERS, fragment),
    ]
}

/// Checks the shadow options against the limits and the device.
pub(crate) fn check_options(ctx: &GpuContext, opts: &RendererOptions) -> Result<(), RenderError> {
    if opts.shadows == ShadowMode::Off {
        return Ok(());
    }
    let limits = ctx.device.limits();
    let size = opts.shadow_size;
    if !(MIN_SHADOW_SIZE..=MAX_SHADOW_SIZE).contains(&size) {
        return Err(RenderError::Invalid(format!(
            "shadow map size {size}: must be {MIN_SHADOW_SIZE}..={MAX_SHADOW_SIZE} texels"
        )));
    }
    if size > limits.max_texture_dimension_2d {
        return Err(RenderError::Invalid(format!(
            "shadow map size {size}: this GPU ({}) allows at most {} texels per side",
            ctx.info.name, limits.max_texture_dimension_2d
        )));
    }
    if opts.shadow_budget > limits.max_texture_array_layers {
        return Err(RenderError::Invalid(format!(
            "{} shadow-map layers: this GPU ({}) holds at most {} layers in a texture array",
            opts.shadow_budget, ctx.info.name, limits.max_texture_array_layers
        )));
    }
    Ok(())
}

/// The shadow-map texture, the lookup resources and the depth pass.
pub(crate) struct ShadowMaps {
    pub size: u32,
    budget: u32,
    /// Sampled view of every layer (`D2Array`).
    view: wgpu::TextureView,
    /// One attachment view per allocated layer (none until a frame needs one:
    /// the sampled view is then a 1×1 placeholder).
    layer_views: Vec<wgpu::TextureView>,
    sampler: wgpu::Sampler,
    layer_buffer: wgpu::Buffer,
    pass_buffer: wgpu::Buffer,
    pass_group: wgpu::BindGroup,
    pipeline: Option<wgpu::RenderPipeline>,
    /// Layers the current frame uses.
    pub used: u32,
    /// Which of them the frame renders (the others still hold their depths:
    /// `shadow_cache.rs` has the rule).
    stale: Vec<bool>,
    cache: ShadowCache,
    /// Keep layers between frames (`RendererOptions::shadow_cache`).
    caching: bool,
    /// Lights that lost their shadows last frame (warn when it changes).
    last_lost: usize,
}

fn array_texture(
    device: &wgpu::Device,
    size: u32,
    layers: u32,
) -> (wgpu::TextureView, Vec<wgpu::TextureView>) {
    let label = format!("deferred shadow maps ({size}x{size}, {layers} layers)");
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&label),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(&format!("{label} array view")),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let layer_views = (0..layers)
        .map(|i| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("deferred shadow map layer {i}")),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: i,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    (view, layer_views)
}

/// The depth pass's group: the light matrices of the layer drawn (a dynamic
/// offset into `pass_buffer`) and the instance transforms.
fn pass_group(
    device: &wgpu::Device,
    pass_buffer: &wgpu::Buffer,
    instance_buffer: &wgpu::Buffer,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let pass_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("deferred shadow pass group"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(64),
                },
                count: None,
            },
            storage_entry(1, wgpu::ShaderStages::VERTEX),
        ],
    });
    let pass_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("deferred shadow pass group"),
        layout: &pass_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: pass_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(64),
                }),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: instance_buffer.as_entire_binding(),
            },
        ],
    });
    (pass_layout, pass_group)
}

impl ShadowMaps {
    /// The resources for `opts` (checked with [`check_options`]); the texture
    /// grows to the layers a frame needs.
    pub fn new(
        ctx: &GpuContext,
        opts: &RendererOptions,
        geometry: &Geometry,
    ) -> Result<ShadowMaps, RenderError> {
        check_options(ctx, opts)?;
        let slots = u64::from(opts.shadow_budget.max(1));
        let on = opts.shadows != ShadowMode::Off;
        let filter = if opts.shadows == ShadowMode::Pcf {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        Ok(ctx.scoped("deferred shadow maps", |device| {
            let (view, _) = array_texture(device, 1, 1);
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("deferred shadow comparison sampler"),
                mag_filter: filter,
                min_filter: filter,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            });
            let layer_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("deferred shadow layers"),
                size: slots * std::mem::size_of::<GpuShadowLayer>() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let pass_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("deferred shadow pass matrices"),
                size: slots * PASS_STRIDE,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let (pass_layout, pass_group) =
                pass_group(device, &pass_buffer, &geometry.instance_buffer);
            let pipeline = on.then(|| pipeline(device, &pass_layout));
            ShadowMaps {
                size: opts.shadow_size,
                budget: opts.shadow_budget,
                view,
                layer_views: Vec::new(),
                sampler,
                layer_buffer,
                pass_buffer,
                pass_group,
                pipeline,
                used: 0,
                stale: Vec::new(),
                cache: ShadowCache::default(),
                caching: opts.shadow_cache,
                last_lost: 0,
            }
        })?)
    }

    /// Bytes of the shadow-map texture now allocated.
    pub fn bytes(&self) -> u64 {
        u64::from(self.size).pow(2) * 4 * self.layer_views.len() as u64
    }

    /// The group 0 entries of the lookups.
    pub fn g0_entries(&self) -> [wgpu::BindGroupEntry<'_>; 3] {
        [
            wgpu::BindGroupEntry {
                binding: BINDING_MAPS,
                resource: wgpu::BindingResource::TextureView(&self.view),
            },
            wgpu::BindGroupEntry {
                binding: BINDING_SAMPLER,
                resource: wgpu::BindingResource::Sampler(&self.sampler),
            },
            wgpu::BindGroupEntry {
                binding: BINDING_LAYERS,
                resource: self.layer_buffer.as_entire_binding(),
            },
        ]
    }

    /// Plans the frame's shadows ([`super::shadows::plan`]: assigns layers to
    /// `lights`), warns when lights lose their shadows to the budget, uploads
    /// the layers, growing the texture if they do not fit, and decides which
    /// layers to render (`changed`: what moved among the casters). Returns
    /// whether the texture was replaced (group 0 must be rebuilt).
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        scene: &str,
        lights: &mut [GpuLight],
        (frame, changed): (&ShadowFrame, &CasterChange),
    ) -> Result<bool, RenderError> {
        let plan = super::shadows::plan(lights, frame);
        // once, and again only when the count changes (not every frame)
        if plan.lights_lost != self.last_lost && plan.lights_lost > 0 {
            log::warn!(
                "{scene}: {} light(s) have no shadows: the frame needs {} shadow-map layers, the budget is {} (raise it with --shadow-layers N, RendererOptions::shadow_budget)",
                plan.lights_lost,
                plan.layers.len() as u32 + plan.layers_lost,
                self.budget
            );
        }
        self.last_lost = plan.lights_lost;
        let needed = plan.layers.len() as u32;
        debug_assert!(needed <= self.budget);
        self.used = needed;
        let mut grown = false;
        let size = self.size;
        if needed as usize > self.layer_views.len() {
            let mib = (u64::from(size).pow(2) * 4 * u64::from(needed)) as f64 / (1 << 20) as f64;
            // Too large for the device's memory is the options' fault: an input
            // error that names them, not a GPU failure.
            let (view, layer_views) = ctx
                .scoped("deferred shadow maps", |device| {
                    array_texture(device, size, needed)
                })
                .map_err(|e| {
                    RenderError::Invalid(format!(
                        "the shadow maps ({needed} layers of {size}x{size}, {mib:.0} MiB) do not fit on this GPU: lower --shadow-size or --shadow-layers ({e})"
                    ))
                })?;
            log::debug!("shadow maps: {needed} layers of {size}x{size} ({mib:.1} MiB)");
            self.view = view;
            self.layer_views = layer_views;
            grown = true;
        }
        let changed = if self.caching {
            changed
        } else {
            &CasterChange::Everywhere
        };
        self.stale = self
            .cache
            .stale_layers(&plan.clip_from_world, changed, grown);
        if needed > 0 {
            ctx.queue
                .write_buffer(&self.layer_buffer, 0, bytemuck::cast_slice(&plan.layers));
            let mut passes = vec![0u8; (u64::from(needed) * PASS_STRIDE) as usize];
            for (i, m) in plan.clip_from_world.iter().enumerate() {
                let at = i * PASS_STRIDE as usize;
                passes[at..at + 64].copy_from_slice(bytemuck::cast_slice(&m.to_cols_array()));
            }
            ctx.queue.write_buffer(&self.pass_buffer, 0, &passes);
        }
        Ok(grown)
    }

    /// What changed among the casters since the previous frame (this frame's
    /// world transforms and deformed poses; remembered for the next).
    pub fn casters_changed(
        &mut self,
        geometry: &Geometry,
        transforms: &[glam::Mat4],
        poses: &[crate::scene::InstancePose],
    ) -> CasterChange {
        self.cache.casters_changed(geometry, transforms, poses)
    }

    /// Layers the current frame renders (of [`ShadowMaps::used`]).
    pub fn rendered(&self) -> u32 {
        self.stale.iter().filter(|&&s| s).count() as u32
    }

    /// Renders the frame's stale layers (one pass each; one timed entry,
    /// "shadow maps", spans them all). Returns the draw calls.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &Geometry,
        names: &mut Vec<String>,
        timer: Option<&GpuTimer>,
    ) -> usize {
        let Some(pipeline) = &self.pipeline else {
            return 0;
        };
        let todo: Vec<u32> = (0..self.used).filter(|&i| self.stale[i as usize]).collect();
        if todo.is_empty() {
            return 0;
        }
        let timed = names.len() as u32;
        // the name stays the same whichever layers a frame renders (per-pass
        // medians over a sequence go by name); `RenderStats` has the count
        names.push(format!("shadow maps ({} layers)", self.used));
        let mut draws = 0;
        for (k, &i) in todo.iter().enumerate() {
            let (first, last) = (k == 0, k + 1 == todo.len());
            // the first pass writes the start, the last the end (wgpu refuses a
            // pass with neither)
            let timestamp_writes = timer
                .and_then(|t| t.pass_writes(timed))
                .filter(|_| first || last)
                .map(|w| wgpu::RenderPassTimestampWrites {
                    beginning_of_pass_write_index: w
                        .beginning_of_pass_write_index
                        .filter(|_| first),
                    end_of_pass_write_index: w.end_of_pass_write_index.filter(|_| last),
                    ..w
                });
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&format!("shadow map layer {i}")),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.layer_views[i as usize],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(pipeline);
            rp.set_bind_group(0, &self.pass_group, &[(u64::from(i) * PASS_STRIDE) as u32]);
            rp.set_vertex_buffer(0, geometry.vertex_buffer.slice(..));
            rp.set_index_buffer(geometry.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            // opaque and MASK batches; BLEND instances are not in `batches`
            for b in &geometry.batches {
                rp.draw_indexed(b.indices.clone(), b.base_vertex, b.instances.clone());
                draws += 1;
            }
        }
        draws
    }
}

/// The depth-only pipeline: positions from the scene's vertex buffer, no
/// fragment stage, no culling, slope-scaled bias.
fn pipeline(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::RenderPipeline {
    let label = "deferred shadow depth pipeline";
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("deferred shadow depth shader"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    let attrs = wgpu::vertex_attr_array![0 => Float32x3];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("fx_vs_shadow"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attrs,
            })],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: wgpu::StencilState::default(),
            bias: BIAS,
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}
