//! Prefiltering an environment map on the GPU, once per map (the passes are in
//! `prefilter.wgsl`; the method is Krivanek and Colbert's filtered importance
//! sampling, as the Khronos glTF Sample Viewer's `ibl_filtering.frag` and
//! Filament's `libs/ibl` use it):
//!
//! 1. the equirectangular map → a source cube map of side `S` (the map's width / 4
//!    rounded up to a power of two, 16 ..= [`MAX_FACE`]) with a box-filtered mip
//!    chain down to 1×1;
//! 2. the specular cube map: side `S`, `L = log2(S) − 1` levels (down to 4×4);
//!    level `m` holds the radiance prefiltered with the GGX lobe of perceptual
//!    roughness [`level_roughness`](super::level_roughness)`(m, L)` (0, 0.1,
//!    0.2, 0.3, 0.45, 0.7, 1 for seven levels; level 0 is a copy of the
//!    source);
//!    shading reads it trilinearly between the two levels that bracket the
//!    surface's roughness, at the fraction linear in the lobes' spread
//!    (environment.wgsl `fx_env_specular_level`). Narrow lobes (roughness below [`CONVOLVED_ROUGHNESS`]) are
//!    importance-sampled ([`SPECULAR_SAMPLES`] per texel, filtered importance
//!    sampling); wide ones are summed exactly over every texel of the map made
//!    into a [`CONVOLVED_SIDE`]² cube on the CPU ([`cube_texels`](super::small_cube::cube_texels): no noise; its
//!    5.6° texels are much finer than those lobes);
//! 3. the irradiance cube map: [`IRRADIANCE_FACE`]² per face, the cosine-weighted
//!    mean radiance (irradiance / π), summed the same exact way.
//!
//! The sun of a real map is the hard case: a few texels hold most of the energy;
//! the filtered importance sampling reads it from a level where it is spread
//! over the sample's solid angle, so levels come out smooth rather than
//! speckled (at the price of a slight extra blur).

use super::bright;
use super::small_cube::cube_texels;
use crate::gpu::context::{GpuContext, GpuError};
use crate::gpu::fullscreen::{begin_color_pass, fullscreen_pipeline};
use crate::scene::environment::Equirect;
use crate::scene::EnvironmentMap;
use wgpu::util::DeviceExt;

/// Largest side of the source and specular cube faces.
pub const MAX_FACE: u32 = 512;
/// Side of the irradiance cube faces.
pub const IRRADIANCE_FACE: u32 = 16;
/// GGX importance samples per texel of the specular levels of roughness below
/// [`CONVOLVED_ROUGHNESS`] (level 1, level 2, ...; the last for the rest).
pub const SPECULAR_SAMPLES: [u32; 4] = [128, 512, 512, 512];
/// Levels of at least this roughness, and the irradiance, are summed over
/// every texel of the source's [`CONVOLVED_SIDE`]² level instead.
pub const CONVOLVED_ROUGHNESS: f32 = 0.65;
pub const CONVOLVED_SIDE: u32 = 16;
/// Side of the DFG table and its samples per texel.
pub const DFG_SIZE: u32 = 64;
pub const DFG_SAMPLES: u32 = 1024;

pub(crate) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// `Prefilter` of prefilter.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuPrefilter {
    pub face: u32,
    pub distribution: u32,
    pub samples: u32,
    pub _p0: u32,
    pub source_size: f32,
    pub roughness: f32,
    pub size: f32,
    pub max_lod: f32,
}

/// The prefiltering pipelines (created once per renderer, on first use).
pub(crate) struct PrefilterPipelines {
    equirect: wgpu::RenderPipeline,
    downsample: wgpu::RenderPipeline,
    filter: wgpu::RenderPipeline,
    convolve: wgpu::RenderPipeline,
    pub(super) dfg: wgpu::RenderPipeline,
    /// Linear and mipmapped; repeats across u.
    sampler: wgpu::Sampler,
}

impl PrefilterPipelines {
    pub fn new(ctx: &GpuContext) -> Result<PrefilterPipelines, GpuError> {
        ctx.scoped("environment prefiltering pipelines", |device| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("environment prefiltering shaders"),
                source: wgpu::ShaderSource::Wgsl(
                    include_str!("../../../shaders/render/environment_prefilter.wgsl").into(),
                ),
            });
            let pipeline = |fs: &str| {
                fullscreen_pipeline(
                    device,
                    &format!("environment prefiltering {fs}"),
                    None,
                    (&module, "vs_fullscreen"),
                    (&module, fs),
                    FORMAT,
                    None,
                )
            };
            PrefilterPipelines {
                equirect: pipeline("fs_equirect"),
                downsample: pipeline("fs_downsample"),
                filter: pipeline("fs_filter"),
                convolve: pipeline("fs_convolve"),
                dfg: pipeline("fs_dfg"),
                sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("environment prefiltering sampler"),
                    address_mode_u: wgpu::AddressMode::Repeat,
                    address_mode_v: wgpu::AddressMode::ClampToEdge,
                    address_mode_w: wgpu::AddressMode::ClampToEdge,
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    mipmap_filter: wgpu::MipmapFilterMode::Linear,
                    ..Default::default()
                }),
            }
        })
    }
}

/// The prefiltered maps of one environment.
pub(crate) struct Prefiltered {
    pub specular: wgpu::Texture,
    pub specular_view: wgpu::TextureView,
    pub irradiance: wgpu::Texture,
    pub irradiance_view: wgpu::TextureView,
    /// Levels of the specular map (its roughness step is 1 / (levels − 1)).
    pub levels: u32,
    /// Side of the specular map's level 0.
    pub size: u32,
    /// The map's bright cells, taken out of levels 1 and on (bright.rs).
    pub bright: Vec<super::bright::BrightCell>,
    /// GPU and CPU time to make them (upload included), milliseconds.
    pub ms: f64,
}

/// The `n` GGX importance samples of perceptual roughness `roughness` about
/// +Z (the split sum's n = v = r) that lie above the horizon: the reflected
/// direction (xyz) and the source level it reads (w), by filtered importance
/// sampling: half the log2 of the ratio of the sample's solid angle `1 / (n
/// pdf)`, `pdf = D(n·h) / 4`, to a texel's `4π / (6 S²)` of a source of side
/// `source_size` (the Khronos viewer's formula leaves out the 4π and reads
/// about 1.8 levels coarser: measurably too blurry against a CPU convolution).
/// Hammersley points, as in prefilter.wgsl's `fs_dfg`.
pub(crate) fn lobe_samples(
    roughness: f32,
    n: u32,
    source_size: u32,
    max_lod: f32,
) -> Vec<[f32; 4]> {
    use std::f32::consts::PI;
    let alpha = (roughness * roughness).max(1e-3);
    let a2 = alpha * alpha;
    let texel = 4.0 * PI / (6.0 * (source_size * source_size) as f32);
    (0..n)
        .filter_map(|i| {
            let (x1, x2) = (
                i as f32 / n as f32,
                i.reverse_bits() as f32 * 2.328_306_4e-10,
            );
            let cos_t = ((1.0 - x2) / (1.0 + (a2 - 1.0) * x2)).max(0.0).sqrt();
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = 2.0 * PI * x1;
            let h = [sin_t * phi.cos(), sin_t * phi.sin(), cos_t];
            let l = [
                2.0 * h[2] * h[0],
                2.0 * h[2] * h[1],
                2.0 * h[2] * h[2] - 1.0,
            ];
            if l[2] <= 0.0 {
                return None;
            }
            let d = cos_t * cos_t * (a2 - 1.0) + 1.0;
            let pdf = a2 / (PI * d * d) * 0.25;
            let lod =
                (0.5 * (1.0 / (n as f32 * pdf.max(1e-12)) / texel).log2()).clamp(0.0, max_lod);
            Some([l[0], l[1], l[2], lod])
        })
        .collect()
}

/// Side of the source cube for a map `width` texels wide.
pub fn face_size(width: u32) -> u32 {
    (width / 4).max(1).next_power_of_two().clamp(16, MAX_FACE)
}

/// Levels of the specular map of side `size`: down to 4×4 (the roughness-1
/// lobe is over 60° wide; a 4×4 face's texels are 22.5°).
pub fn specular_levels(size: u32) -> u32 {
    (size.trailing_zeros()).saturating_sub(1).max(2)
}

fn cube(device: &wgpu::Device, label: &str, size: u32, levels: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 6,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// A 2D view of one face of one level.
fn face_view(t: &wgpu::Texture, level: u32, face: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some("environment cube face"),
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_mip_level: level,
        mip_level_count: Some(1),
        base_array_layer: face,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

/// The whole texture as a cube map.
pub(crate) fn cube_view(t: &wgpu::Texture, label: &str) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        dimension: Some(wgpu::TextureViewDimension::Cube),
        ..Default::default()
    })
}

/// One full-screen pass of `pipeline` into `target` with `resources` (binding,
/// resource) and, when given, the uniform `params` at binding 0.
pub(super) fn pass(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    target: &wgpu::TextureView,
    params: Option<GpuPrefilter>,
    resources: &[(u32, wgpu::BindingResource<'_>)],
) {
    let buffer = params.map(|p| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment prefiltering parameters"),
            contents: bytemuck::bytes_of(&p),
            usage: wgpu::BufferUsages::UNIFORM,
        })
    });
    let mut entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .map(|(b, r)| wgpu::BindGroupEntry {
            binding: *b,
            resource: r.clone(),
        })
        .collect();
    if let Some(b) = &buffer {
        entries.push(wgpu::BindGroupEntry {
            binding: 0,
            resource: b.as_entire_binding(),
        });
    }
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("environment prefiltering group"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let clear = wgpu::LoadOp::Clear(wgpu::Color::BLACK);
    let mut rp = begin_color_pass(
        encoder,
        "environment prefiltering pass",
        target,
        clear,
        None,
    );
    rp.set_pipeline(pipeline);
    rp.set_bind_group(0, &group, &[]);
    rp.draw(0..3, 0..1);
}

/// [`pass`] into each face of level `level` of the cube `target`, with the
/// parameters `params(face)`.
fn each_face(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    (target, level): (&wgpu::Texture, u32),
    params: impl Fn(u32) -> GpuPrefilter,
    resources: &[(u32, wgpu::BindingResource<'_>)],
) {
    for face in 0..6 {
        let view = face_view(target, level, face);
        pass(
            device,
            encoder,
            pipeline,
            &view,
            Some(params(face)),
            resources,
        );
    }
}

/// The face size and mip levels of one prefiltering.
#[derive(Clone, Copy)]
struct Sizes {
    /// The source's and the specular map's face size.
    size: u32,
    /// Levels of the source cube (down to 1×1).
    source_levels: u32,
    /// GGX levels of the specular map.
    levels: u32,
}

impl Sizes {
    /// The sizes for an equirectangular map `width` texels wide.
    fn of(width: u32) -> Sizes {
        let size = face_size(width);
        Sizes {
            size,
            source_levels: size.trailing_zeros() + 1,
            levels: specular_levels(size),
        }
    }

    /// The parameters of one face's pass into a level `side` texels wide.
    fn params(
        &self,
        face: u32,
        distribution: u32,
        samples: u32,
        roughness: f32,
        side: u32,
    ) -> GpuPrefilter {
        GpuPrefilter {
            face,
            distribution,
            samples,
            _p0: 0,
            source_size: self.size as f32,
            roughness,
            size: side as f32,
            max_lod: (self.source_levels - 1) as f32,
        }
    }
}

/// The passes of one prefiltering, recorded into one encoder.
struct Recorder<'a> {
    device: &'a wgpu::Device,
    encoder: wgpu::CommandEncoder,
    pipes: &'a PrefilterPipelines,
    sizes: Sizes,
}

impl Recorder<'_> {
    /// The source cube: level 0 from the equirectangular map, every further
    /// level downsampled from the one above.
    fn fill_source(&mut self, source: &wgpu::Texture, equirect: &wgpu::Texture) {
        let (device, pipes, sizes) = (self.device, self.pipes, self.sizes);
        let equirect_view = equirect.create_view(&Default::default());
        each_face(
            device,
            &mut self.encoder,
            &pipes.equirect,
            (source, 0),
            |face| sizes.params(face, 0, 0, 0.0, sizes.size),
            &[
                (1, wgpu::BindingResource::TextureView(&equirect_view)),
                (4, wgpu::BindingResource::Sampler(&pipes.sampler)),
            ],
        );
        for level in 1..sizes.source_levels {
            for face in 0..6 {
                let above = face_view(source, level - 1, face);
                pass(
                    device,
                    &mut self.encoder,
                    &pipes.downsample,
                    &face_view(source, level, face),
                    None,
                    &[(3, wgpu::BindingResource::TextureView(&above))],
                );
            }
        }
    }

    /// Level 0 of the specular map: roughness 0, the source itself.
    fn copy_mirror_level(&mut self, source: &wgpu::Texture, specular: &wgpu::Texture) {
        let size = self.sizes.size;
        self.encoder.copy_texture_to_texture(
            source.as_image_copy(),
            specular.as_image_copy(),
            wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 6,
            },
        );
    }

    /// The specular map's levels from 1 on: each the GGX lobe of its
    /// roughness, sampled from the source cube, or convolved from the small
    /// cube from [`CONVOLVED_ROUGHNESS`] on.
    fn filter_specular(
        &mut self,
        source: &wgpu::Texture,
        specular: &wgpu::Texture,
        small: &wgpu::Buffer,
    ) {
        let (device, pipes, sizes) = (self.device, self.pipes, self.sizes);
        let (size, levels) = (sizes.size, sizes.levels);
        let source_cube = cube_view(source, "environment source cube");
        for level in 1..levels {
            let side = size >> level;
            let roughness = super::level_roughness(level, levels);
            let convolved = roughness >= CONVOLVED_ROUGHNESS;
            let samples = SPECULAR_SAMPLES[(level as usize - 1).min(SPECULAR_SAMPLES.len() - 1)];
            let lobe = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("environment prefiltering lobe samples"),
                contents: bytemuck::cast_slice(&lobe_samples(
                    roughness,
                    samples,
                    size,
                    (sizes.source_levels - 1) as f32,
                )),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let (pipeline, resources) = if convolved {
                (&pipes.convolve, [(7, small.as_entire_binding())].to_vec())
            } else {
                (
                    &pipes.filter,
                    [
                        (2, wgpu::BindingResource::TextureView(&source_cube)),
                        (4, wgpu::BindingResource::Sampler(&pipes.sampler)),
                        (6, lobe.as_entire_binding()),
                    ]
                    .to_vec(),
                )
            };
            each_face(
                device,
                &mut self.encoder,
                pipeline,
                (specular, level),
                |face| sizes.params(face, 0, samples, roughness, side),
                &resources,
            );
        }
    }

    /// The irradiance cube, convolved from the small cube.
    fn convolve_irradiance(&mut self, irradiance: &wgpu::Texture, small: &wgpu::Buffer) {
        let sizes = self.sizes;
        each_face(
            self.device,
            &mut self.encoder,
            &self.pipes.convolve,
            (irradiance, 0),
            |face| sizes.params(face, 1, 0, 1.0, IRRADIANCE_FACE),
            &[(7, small.as_entire_binding())],
        );
    }
}

/// Map `m` (of [`EnvironmentMap`] `map`) as an `Rgba16Float` texture (alpha 1).
fn upload_equirect(
    ctx: &GpuContext,
    map: &EnvironmentMap,
    m: &Equirect,
) -> Result<wgpu::Texture, GpuError> {
    let texels: Vec<half::f16> = m
        .texels
        .iter()
        .flat_map(|t| [t.x, t.y, t.z, 1.0].map(half::f16::from_f32))
        .collect();
    ctx.upload_texture(
        &format!("environment map {}", map.name),
        m.width,
        m.height,
        FORMAT,
        bytemuck::cast_slice(&texels),
        wgpu::TextureUsages::empty(),
    )
}

/// Prefilters `map` (blocks until the GPU is done, so that [`Prefiltered::ms`]
/// is the real cost): level 0 of the specular map and the irradiance from the
/// whole map, the further levels from the residual of its bright cells
/// ([`bright::split`]).
pub(crate) fn prefilter(
    ctx: &GpuContext,
    pipes: &PrefilterPipelines,
    map: &EnvironmentMap,
) -> Result<Prefiltered, GpuError> {
    let start = std::time::Instant::now();
    let m = &map.map;
    let split = bright::split(m);
    let equirect = upload_equirect(ctx, map, m)?;
    let residual = if split.cells.is_empty() {
        None
    } else {
        Some(upload_equirect(ctx, map, &split.residual)?)
    };
    let sizes = Sizes::of(m.width);
    let Sizes { size, levels, .. } = sizes;
    let made = ctx.scoped("environment prefiltering", |device| {
        let source = cube(device, "environment source cube", size, sizes.source_levels);
        let specular = cube(
            device,
            "environment specular cube (GGX levels)",
            size,
            levels,
        );
        let irradiance = cube(device, "environment irradiance cube", IRRADIANCE_FACE, 1);
        let encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("environment prefiltering"),
        });
        let mut rec = Recorder {
            device,
            encoder,
            pipes,
            sizes,
        };
        let small = |label: &str, m: &Equirect| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&cube_texels(m, CONVOLVED_SIDE)),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        rec.fill_source(&source, &equirect);
        rec.copy_mirror_level(&source, &specular);
        let whole = small("environment small cube texels", m);
        rec.convolve_irradiance(&irradiance, &whole);
        let residual_small = match &residual {
            Some(r) => {
                rec.fill_source(&source, r);
                small(
                    "environment small cube texels (residual of the bright cells)",
                    &split.residual,
                )
            }
            None => whole,
        };
        rec.filter_specular(&source, &specular, &residual_small);
        ctx.queue.submit([rec.encoder.finish()]);
        let specular_view = cube_view(&specular, "environment specular cube");
        let irradiance_view = cube_view(&irradiance, "environment irradiance cube");
        (specular, specular_view, irradiance, irradiance_view)
    })?;
    ctx.wait_idle()?;
    let (specular, specular_view, irradiance, irradiance_view) = made;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    log::info!(
        "{}: environment prefiltered in {ms:.0} ms ({}x{} map, {size}² faces, {levels} GGX levels, {IRRADIANCE_FACE}² irradiance, {} bright cells)",
        map.name,
        m.width,
        m.height,
        split.cells.len()
    );
    Ok(Prefiltered {
        specular,
        specular_view,
        irradiance,
        irradiance_view,
        levels,
        size,
        bright: split.cells,
        ms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lobe_samples_lie_above_the_horizon_and_read_coarser_levels_off_centre() {
        let s = lobe_samples(0.5, 128, 256, 8.0);
        assert!(s.len() > 100 && s.len() <= 128);
        for v in &s {
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-4 && v[2] > 0.0 && (0.0..=8.0).contains(&v[3]));
        }
        // the first sample (xi.y = 0) is the lobe's centre: the finest level
        let centre = s.iter().find(|v| v[2] > 0.9999).unwrap()[3];
        let far = s.iter().map(|v| v[3]).fold(0.0f32, f32::max);
        assert!(far > centre + 1.0, "centre {centre}, far {far}");
    }
}
