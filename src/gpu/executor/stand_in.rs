//! A storage texture standing in for the caller's output.
//!
//! Under compute execution the pass that writes the caller's output runs as a
//! compute dispatch only where that texture can be bound for storage. The
//! common output, an `rgba8unorm-srgb` image for a PNG, a y4m or the viewer,
//! cannot: sRGB formats are never storage formats. That pass used to fall back
//! to a full-screen fragment pass, which on an NVIDIA H200 cost 0.15 ms for a
//! tonemap and 5.7 ms for SSAO's final pass at 1080p, against 0.03 and 0.16 ms
//! as compute dispatches (`../shared/perf/README.md`, bench/gpu.sh).
//!
//! Here the dispatch writes a texture of the storage format instead (for an
//! sRGB output its raw twin, with the compute wrapper encoding sRGB in the
//! shader), and the frame copies that into the output. Formats that differ only
//! in their sRGB suffix copy texel for texel, so the output holds the same
//! bytes the fragment path would have written; the copy costs one read and one
//! write of the image (16 MiB for 1080p rgba8; not yet timed on a GPU).
//!
//! A compute-native pass stores in its shader's own format (`rgba16float`,
//! say). Where that is not the output's, the stand-in holds the pass's values
//! and a second dispatch converts them into a texture of the output's raw
//! format, encoding sRGB where the fragment path's target view would have
//! (`shaders/engine/_convert.wgsl`); that texture is copied into the output.
//!
//! A caller's output qualifies when it has `COPY_DST`, one mip level and one
//! sample, and its format is the pass's storage format up to the sRGB suffix
//! (copied) or the pass converts; a BGRA window surface and the GL backend keep
//! the fragment path, and so does fragment execution where the pass can be
//! drawn. A compute-native pass converts only into an `rgba8-srgb` output,
//! which no adapter stores to: another mismatch of its storage format and its
//! `OUT.FORMAT` stays the error it is.

use crate::gpu::bindings::texture_entry;
use crate::gpu::context::GpuContext;
use crate::gpu::formats::wgsl_storage_format;
use crate::gpu::transfer::texture_2d;
use crate::shader::compute::SRGB_ENCODE;

/// The conversion dispatch: `src` read texel by texel, stored to `dst`.
const CONVERT_WGSL: &str = include_str!("../../../shaders/engine/_convert.wgsl");

/// Invocations per conversion workgroup, in x and y.
const CONVERT_WORKGROUP: u32 = 8;

/// A texture of the stand-in and its view.
struct Image {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

/// The conversion of a compute-native pass's values into the output's format.
struct Conversion {
    /// The output's raw format, sRGB encoded when `encode`.
    raw: Image,
    encode: bool,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
}

/// The stand-in textures, kept from frame to frame.
pub(super) struct StandIn {
    stored: Image,
    conversion: Option<Conversion>,
}

/// What one frame's output pass writes instead of the caller's output: the
/// caller image it replaces and the stand-in's storage view, then what to do
/// after the dispatch.
pub(super) struct StandInUse {
    pub caller_index: usize,
    pub view: wgpu::TextureView,
    /// The texture copied into the output (the stored one or the converted).
    from: wgpu::Texture,
    to: wgpu::Texture,
    /// The conversion dispatch before the copy: pipeline, bind group, size.
    convert: Option<(wgpu::ComputePipeline, wgpu::BindGroup, (u32, u32))>,
}

impl StandInUse {
    /// The caller's views with the output replaced by the stand-in.
    pub fn caller_views(&self, caller: &[wgpu::TextureView]) -> Vec<wgpu::TextureView> {
        let mut views = caller.to_vec();
        views[self.caller_index] = self.view.clone();
        views
    }

    /// Record the conversion (where there is one) and the copy into the
    /// caller's output.
    pub fn finish(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some((pipeline, bind_group, (w, h))) = &self.convert {
            let mut cp = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("fxgraph output conversion"),
                timestamp_writes: None,
            });
            cp.set_pipeline(pipeline);
            cp.set_bind_group(0, bind_group, &[]);
            cp.dispatch_workgroups(
                w.div_ceil(CONVERT_WORKGROUP),
                h.div_ceil(CONVERT_WORKGROUP),
                1,
            );
        }
        encoder.copy_texture_to_texture(
            self.from.as_image_copy(),
            self.to.as_image_copy(),
            self.to.size(),
        );
    }
}

/// Whether `output` can take the values of a pass storing `storage` through a
/// stand-in: a copy where the formats differ at most in sRGB-ness, else a
/// conversion where the pass has one.
fn qualifies(output: &wgpu::Texture, storage: wgpu::TextureFormat, converts: bool) -> bool {
    output.usage().contains(wgpu::TextureUsages::COPY_DST)
        && output.mip_level_count() == 1
        && output.sample_count() == 1
        && output.dimension() == wgpu::TextureDimension::D2
        && (converts || output.format().remove_srgb_suffix() == storage)
}

/// What the pass writing the caller's output stores: the caller image it
/// writes, the storage format, and whether its values are converted into the
/// output (`Some(encode)`, a compute-native pass), from its compute path.
pub(super) struct OutputTarget {
    pub caller_index: usize,
    pub storage: wgpu::TextureFormat,
    pub convert: Option<bool>,
}

/// The stand-in for a pass writing `target` this frame, where that output
/// qualifies (module docs); `None` on the GL backend. The textures are kept in
/// `slot`, made on first use and remade when the output's size or format
/// changes.
pub(super) fn for_output(
    slot: &mut Option<StandIn>,
    ctx: &GpuContext,
    target: OutputTarget,
    caller: &[wgpu::TextureView],
) -> Option<StandInUse> {
    if ctx.info.backend == wgpu::Backend::Gl {
        return None;
    }
    let OutputTarget {
        caller_index,
        storage,
        convert,
    } = target;
    let output = caller.get(caller_index)?.texture().clone();
    let raw = output.format().remove_srgb_suffix();
    let encode = convert.filter(|_| raw != storage);
    if !qualifies(&output, storage, encode.is_some()) {
        return None;
    }
    let fits = slot.as_ref().is_some_and(|s| {
        s.stored.texture.size() == output.size()
            && s.stored.texture.format() == storage
            && s.conversion
                .as_ref()
                .map(|c| (c.raw.texture.format(), c.encode))
                == encode.map(|e| (raw, e))
    });
    if !fits {
        let cache = ctx.pipeline_cache.clone();
        let made = ctx.scoped("output stand-in", |device| {
            let stored = image(device, &output, storage);
            let conversion =
                encode.map(|e| conversion(device, cache.as_ref(), &stored, (&output, raw), e));
            StandIn { stored, conversion }
        });
        match made {
            Ok(s) => *slot = Some(s),
            Err(e) => {
                log::warn!("the output pass stays a fragment pass: {e}");
                return None;
            }
        }
    }
    let s = slot.as_ref().expect("made above");
    let (from, convert) = match &s.conversion {
        Some(c) => (
            c.raw.texture.clone(),
            Some((
                c.pipeline.clone(),
                c.bind_group.clone(),
                (output.width(), output.height()),
            )),
        ),
        None => (s.stored.texture.clone(), None),
    };
    Some(StandInUse {
        caller_index,
        view: s.stored.view.clone(),
        from,
        to: output,
        convert,
    })
}

/// A storage texture of `format` the size of `output`.
fn image(device: &wgpu::Device, output: &wgpu::Texture, format: wgpu::TextureFormat) -> Image {
    let usage = wgpu::TextureUsages::STORAGE_BINDING
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::TEXTURE_BINDING;
    let size = (output.width(), output.height());
    let label = format!("fxgraph output stand-in {format:?}");
    let texture = device.create_texture(&texture_2d(&label, size, format, usage, &[]));
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(&format!("{label} view")),
        ..Default::default()
    });
    Image { texture, view }
}

/// The conversion of `stored` into a new texture of `raw` (the output's format
/// without its sRGB suffix), sRGB-encoded when `encode`.
fn conversion(
    device: &wgpu::Device,
    cache: Option<&wgpu::PipelineCache>,
    stored: &Image,
    (output, raw): (&wgpu::Texture, wgpu::TextureFormat),
    encode: bool,
) -> Conversion {
    let target = image(device, output, raw);
    let name = wgsl_storage_format(raw).unwrap_or("rgba8unorm");
    let source = CONVERT_WGSL
        .replace("FXGRAPH_FORMAT", name)
        .replace(
            "FXGRAPH_ENCODE",
            if encode { "fxgraph_srgb_encode" } else { "" },
        )
        .replace(
            "// FXGRAPH_SRGB_ENCODE",
            if encode { SRGB_ENCODE } else { "" },
        );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("fxgraph output conversion"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("fxgraph output conversion bind group layout"),
        entries: &[
            texture_entry(
                0,
                wgpu::ShaderStages::COMPUTE,
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            ),
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: raw,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            },
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("fxgraph output conversion pipeline layout"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("fxgraph output conversion pipeline"),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some("fx_cs_convert"),
        compilation_options: Default::default(),
        cache,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fxgraph output conversion bind group"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&stored.view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&target.view),
            },
        ],
    });
    Conversion {
        raw: target,
        encode,
        pipeline,
        bind_group,
    }
}
