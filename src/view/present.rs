//! Drawing the shown image into the window (`present.wgsl`): placement (fit or a
//! zoom with panning), the before/after split, how values become display codes
//! (8-bit codes as stored, linear light with an exposure, data over a range) and
//! the mark on clipped pixels.

use crate::gpu::bindings::{texture_entry, uniform_entry};
use crate::gpu::context::GpuContext;
use crate::gpu::executor::{bgra_twin, wgpu_format};
use crate::gpu::fullscreen::{begin_color_pass, fullscreen_pipeline};
use crate::gpu::transfer::{create_output, texture_2d};
use crate::script::types::Format;

/// A window surface's configuration on `ctx`: a unorm format where the window
/// offers one (8-bit outputs' codes shown exactly), `COPY_DST` where offered (a
/// 1:1 image is copied into the surface), `size`, vsync or not; `None` when the
/// window offers no format.
pub fn surface_config(
    ctx: &GpuContext,
    surface: &wgpu::Surface<'static>,
    (width, height): (u32, u32),
    vsync: bool,
) -> Option<wgpu::SurfaceConfiguration> {
    let caps = surface.get_capabilities(&ctx.adapter);
    let unorm = |f: &wgpu::TextureFormat| {
        matches!(
            f,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
        )
    };
    let format = caps
        .formats
        .iter()
        .copied()
        .find(unorm)
        .or(caps.formats.first().copied())?;
    let usage =
        wgpu::TextureUsages::RENDER_ATTACHMENT | (caps.usages & wgpu::TextureUsages::COPY_DST);
    Some(wgpu::SurfaceConfiguration {
        usage,
        format,
        width: width.max(1),
        height: height.max(1),
        present_mode: if vsync {
            wgpu::PresentMode::AutoVsync
        } else {
            wgpu::PresentMode::AutoNoVsync
        },
        desired_maximum_frame_latency: 2,
        alpha_mode: caps.alpha_modes[0],
        view_formats: vec![],
        color_space: wgpu::SurfaceColorSpace::Auto,
    })
}

/// The texture format the window's copy of an output of `format` is in: the BGRA
/// twin of an 8-bit format (what window surfaces offer: at 1:1 the output is copied
/// to the screen, not drawn), the plan's own otherwise (and on GL, which cannot
/// view a texture in another format).
pub fn window_output_format(ctx: &GpuContext, format: Format) -> wgpu::TextureFormat {
    let plain = wgpu_format(format);
    match bgra_twin(plain) {
        Some(t) if ctx.info.backend != wgpu::Backend::Gl => t,
        _ => plain,
    }
}

/// The texture the effect's output is recorded into (see [`window_output_format`]).
pub fn window_output(ctx: &GpuContext, width: u32, height: u32, format: Format) -> wgpu::Texture {
    let tf = window_output_format(ctx, format);
    if tf == wgpu_format(format) {
        return create_output(ctx, width, height, format);
    }
    // An sRGB output may be written through a raw view (as `create_output`'s).
    let raw = [wgpu::TextureFormat::Bgra8Unorm];
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::TEXTURE_BINDING;
    let view_formats: &[wgpu::TextureFormat] = if tf == wgpu::TextureFormat::Bgra8UnormSrgb {
        &raw
    } else {
        &[]
    };
    let label = "viewer output (BGRA)";
    ctx.device
        .create_texture(&texture_2d(label, (width, height), tf, usage, view_formats))
}

/// How values are shown (the shader's `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shade {
    /// 8-bit codes as stored (raw view).
    Codes,
    /// Linear light: exposure, clamp, sRGB encoding.
    Colour,
    /// `(v - lo) / (hi - lo)` shown as codes.
    Data,
}

/// A texture to show and the format its values are in.
#[derive(Clone, Copy)]
pub struct Shown<'a> {
    pub texture: &'a wgpu::Texture,
    pub format: Format,
    /// `None`: as the format suggests ([`auto_shade`]).
    pub shade: Option<Shade>,
}

/// How a texture of `format` is shown by default.
pub fn auto_shade(format: Format) -> Shade {
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
pub struct Placement {
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
pub struct Presenter {
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
    let srgb = t.format().is_srgb();
    if srgb && shade == Shade::Codes {
        let raw_format = t.format().remove_srgb_suffix();
        let raw = ctx.scoped("viewer raw view", |_| {
            t.create_view(&wgpu::TextureViewDescriptor {
                label: Some("viewer raw view"),
                format: Some(raw_format),
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
            source: wgpu::ShaderSource::Wgsl(
                include_str!("../../shaders/view/present.wgsl").into(),
            ),
        });
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
        let tex = |binding| {
            texture_entry(
                binding,
                fragment,
                unfilterable,
                wgpu::TextureViewDimension::D2,
            )
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewer present bind group layout"),
            entries: &[tex(0), tex(1), uniform_entry(2, fragment)],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewer present pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = fullscreen_pipeline(
            device,
            "viewer present pipeline",
            Some(&pl),
            (&module, "vs_main"),
            (&module, "fs_main"),
            surface_format,
            None,
        );
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

    /// The copy that shows the image prepared for `place` on `surface`, when one can:
    /// the image is at 1:1 on whole pixels, shown as its stored codes, without a
    /// split, in the surface's format (up to sRGB); the part in the area.
    fn copy_region(
        &self,
        place: &Placement,
        split: bool,
        surface: &wgpu::Texture,
    ) -> Option<(wgpu::Origin3d, wgpu::Origin3d, wgpu::Extent3d)> {
        let c = self.cached.as_ref()?;
        let t = &c.after;
        let fits = t.format().remove_srgb_suffix() == surface.format().remove_srgb_suffix()
            && c.modes.0 == 0
            && !split
            && surface.usage().contains(wgpu::TextureUsages::COPY_DST)
            && place.rect[2] == t.width() as f32
            && place.rect[3] == t.height() as f32;
        if !fits {
            return None;
        }
        let [ax, ay, aw, ah] = place.area.map(i64::from);
        let (x, y) = (place.rect[0] as i64, place.rect[1] as i64);
        let x0 = x.max(ax).max(0);
        let y0 = y.max(ay).max(0);
        let x1 = (x + t.width() as i64)
            .min(ax + aw)
            .min(surface.width() as i64);
        let y1 = (y + t.height() as i64)
            .min(ay + ah)
            .min(surface.height() as i64);
        if x1 <= x0 || y1 <= y0 {
            return None;
        }
        let o = |a: i64, b: i64| wgpu::Origin3d {
            x: a as u32,
            y: b as u32,
            z: 0,
        };
        Some((
            o(x0 - x, y0 - y),
            o(x0, y0),
            wgpu::Extent3d {
                width: (x1 - x0) as u32,
                height: (y1 - y0) as u32,
                depth_or_array_layers: 1,
            },
        ))
    }

    /// Record the window's picture into `encoder`: clear `surface`, the image of the
    /// last `prepare` (`image`: there is one) in its area, copied where
    /// [`Presenter::copy_region`] allows (on lavapipe a copy costs a fraction of a
    /// drawn pass), drawn otherwise; then `overlay` (the panel) over everything.
    ///
    /// `panel`: a texture and the rectangle of it to copy over the frame (the
    /// panel drawn before, `panel_cache.rs`); `overlay`: drawn over the frame.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        surface: &wgpu::Texture,
        view: &wgpu::TextureView,
        place: &Placement,
        image: bool,
        split: bool,
        panel: Option<(&wgpu::Texture, [u32; 4])>,
        overlay: Option<impl FnOnce(&mut wgpu::RenderPass<'static>)>,
    ) {
        let background = wgpu::Color {
            r: 0.02,
            g: 0.02,
            b: 0.02,
            a: 1.0,
        };
        let pass = |encoder: &mut wgpu::CommandEncoder, load| {
            begin_color_pass(encoder, "viewer present", view, load, None).forget_lifetime()
        };
        let copy = if image {
            self.copy_region(place, split, surface)
        } else {
            None
        };
        let (sw, sh) = (surface.width(), surface.height());
        {
            let mut rp = pass(encoder, wgpu::LoadOp::Clear(background));
            if image && copy.is_none() {
                self.draw(&mut rp, place);
            }
        }
        if let (Some((from, to, size)), Some(c)) = (copy, &self.cached) {
            encoder.copy_texture_to_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &c.after,
                    mip_level: 0,
                    origin: from,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyTextureInfo {
                    texture: surface,
                    mip_level: 0,
                    origin: to,
                    aspect: wgpu::TextureAspect::All,
                },
                size,
            );
        }
        if let Some((tex, [x, y, w, h])) = panel {
            let at = wgpu::Origin3d { x, y, z: 0 };
            encoder.copy_texture_to_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: tex,
                    mip_level: 0,
                    origin: at,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyTextureInfo {
                    texture: surface,
                    mip_level: 0,
                    origin: at,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: w.min(sw.saturating_sub(x)),
                    height: h.min(sh.saturating_sub(y)),
                    depth_or_array_layers: 1,
                },
            );
        }
        if let Some(overlay) = overlay {
            let mut rp = pass(encoder, wgpu::LoadOp::Load);
            rp.set_scissor_rect(0, 0, sw, sh);
            overlay(&mut rp);
        }
    }

    /// Draw into `pass` (over the image area of the placement given to `prepare`).
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, place: &Placement) {
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
