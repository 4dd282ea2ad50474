//! Drawing the shown image into the window (`present.wgsl`): placement (fit or a
//! zoom with panning), the before/after split, how values become display codes
//! (8-bit codes as stored, linear light with an exposure, data over a range) and
//! the mark on clipped pixels.

use fxgraph::gpu::context::GpuContext;
use fxgraph::script::types::Format;

/// How values are shown (the shader's `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Shade {
    /// 8-bit codes as stored (raw view).
    Codes,
    /// Linear light: exposure, clamp, sRGB encoding.
    Colour,
    /// `(v - lo) / (hi - lo)` shown as codes.
    Data,
}

/// A texture to show and the format its values are in.
#[derive(Clone, Copy)]
pub(super) struct Shown<'a> {
    pub texture: &'a wgpu::Texture,
    pub format: Format,
    /// `None`: as the format suggests ([`auto_shade`]).
    pub shade: Option<Shade>,
}

/// How a texture of `format` is shown by default.
pub(super) fn auto_shade(format: Format) -> Shade {
    match format {
        Format::Rgba8 | Format::Rgba8Srgb | Format::Rgb10a2 => Shade::Codes,
        Format::Rgba16f | Format::Rgba32f => Shade::Colour,
        Format::R8 | Format::R16f | Format::R32f | Format::Rg16f | Format::Rg32f => Shade::Data,
    }
}

fn channels(format: Format) -> u32 {
    match format {
        Format::R8 | Format::R16f | Format::R32f => 1,
        Format::Rg16f | Format::Rg32f => 2,
        _ => 4,
    }
}

/// Where and how the image is drawn this frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    /// The image's rectangle in surface pixels: x, y, width, height.
    pub rect: [f32; 4],
    /// The area it may cover (the window minus the panel): x, y, width, height.
    pub area: [u32; 4],
    /// Image x (0..1) where "after" starts; 0: no split.
    pub split: f32,
    /// Exposure in stops, for linear-light images.
    pub exposure: f32,
    /// The range of data shown as 0..1.
    pub range: (f32, f32),
    pub mark_clipping: bool,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    rect: [f32; 4],
    split: f32,
    exposure: f32,
    lo: f32,
    hi: f32,
    after_mode: u32,
    before_mode: u32,
    after_channels: u32,
    before_channels: u32,
    flags: u32,
    _pad: [u32; 3],
}

/// The bind group of the textures shown, with the shades asked for and the
/// shader modes their views allow.
struct Cached {
    after: wgpu::Texture,
    before: wgpu::Texture,
    shades: (Shade, Shade),
    modes: (u32, u32),
    bind_group: wgpu::BindGroup,
}

/// The pipeline and what it binds.
pub(super) struct Presenter {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    srgb_surface: bool,
    /// The bind group of the last textures shown and how they are shown.
    cached: Option<Cached>,
}

/// A view of `t` that reads its values in `shade` (the raw view of an sRGB texture
/// for codes), and the mode the shader uses: an sRGB texture without a raw view
/// is decoded by the sampler and shown as linear light.
fn view_for(ctx: &GpuContext, t: &wgpu::Texture, shade: Shade) -> (wgpu::TextureView, u32) {
    let mode = |s: Shade| match s {
        Shade::Codes => 0,
        Shade::Colour => 1,
        Shade::Data => 2,
    };
    if t.format() == wgpu::TextureFormat::Rgba8UnormSrgb && shade == Shade::Codes {
        let raw = ctx.scoped("viewer raw view", |_| {
            t.create_view(&wgpu::TextureViewDescriptor {
                label: Some("viewer raw view"),
                format: Some(wgpu::TextureFormat::Rgba8Unorm),
                ..Default::default()
            })
        });
        if let Ok(v) = raw {
            return (v, 0);
        }
        let v = t.create_view(&wgpu::TextureViewDescriptor {
            label: Some("viewer view"),
            ..Default::default()
        });
        return (v, 1);
    }
    let v = t.create_view(&wgpu::TextureViewDescriptor {
        label: Some("viewer view"),
        ..Default::default()
    });
    (v, mode(shade))
}

impl Presenter {
    pub fn new(ctx: &GpuContext, surface_format: wgpu::TextureFormat) -> Self {
        let device = &ctx.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer present"),
            source: wgpu::ShaderSource::Wgsl(include_str!("present.wgsl").into()),
        });
        let tex = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewer present bind group layout"),
            entries: &[
                tex(0),
                tex(1),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewer present pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("viewer present pipeline"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: surface_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewer present uniforms"),
            size: std::mem::size_of::<ViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Presenter {
            pipeline,
            layout,
            uniform,
            srgb_surface: surface_format.is_srgb(),
            cached: None,
        }
    }

    /// Write the frame's placement and bind `after` and `before` (`None`: no split,
    /// the after image on both sides).
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        after: Shown,
        before: Option<Shown>,
        place: &Placement,
    ) {
        let before_or = before.unwrap_or(after);
        let a_shade = after.shade.unwrap_or(auto_shade(after.format));
        let b_shade = before_or.shade.unwrap_or(auto_shade(before_or.format));
        let hit = self.cached.as_ref().is_some_and(|c| {
            &c.after == after.texture
                && &c.before == before_or.texture
                && c.shades == (a_shade, b_shade)
        });
        if !hit {
            let (av, am) = view_for(ctx, after.texture, a_shade);
            let (bv, bm) = view_for(ctx, before_or.texture, b_shade);
            let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("viewer present bind group"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&av),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&bv),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: self.uniform.as_entire_binding(),
                    },
                ],
            });
            self.cached = Some(Cached {
                after: after.texture.clone(),
                before: before_or.texture.clone(),
                shades: (a_shade, b_shade),
                modes: (am, bm),
                bind_group,
            });
        }
        let modes = self.cached.as_ref().expect("made above").modes;
        let magnified = place.rect[2] >= after.texture.width() as f32 - 0.5;
        let u = ViewUniform {
            rect: place.rect,
            split: if before.is_some() { place.split } else { 0.0 },
            exposure: 2f32.powf(place.exposure),
            lo: place.range.0,
            hi: place.range.1,
            after_mode: modes.0,
            before_mode: modes.1,
            after_channels: channels(after.format),
            before_channels: channels(before_or.format),
            flags: u32::from(place.mark_clipping)
                | (u32::from(magnified) << 1)
                | (u32::from(self.srgb_surface) << 2),
            _pad: [0; 3],
        };
        ctx.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&u));
    }

    /// Draw into `pass` (over the image area of the placement given to `prepare`).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, place: &Placement) {
        let Some(c) = &self.cached else {
            return;
        };
        let [x, y, w, h] = place.area;
        if w == 0 || h == 0 {
            return;
        }
        pass.set_scissor_rect(x, y, w, h);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &c.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
