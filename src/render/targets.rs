//! The frame's render targets: the compressed G-buffer (Tang et al., table 2, plus
//! the Cook-Torrance inputs and the lighting-model id), the light buffers, the HDR
//! scene and the AUX images, with the bind groups that read them.
//!
//! | target | format | content |
//! |---|---|---|
//! | albedo | `Rgba8UnormSrgb` | rgb diffuse colour, a = material id / 255 |
//! | normal | `Rgb10a2Unorm` | rg = view-space normal in two channels ([`super::NormalEncoding`]), b = roughness |
//! | specular | `Rgba8UnormSrgb` | rgb specular colour F0, a = lighting model id / 255 |
//! | depth | `Depth32Float` | hardware depth; positions come from the inverse projection |
//!
//! 16 bytes per pixel ([`GBUFFER_BYTES_COMPRESSED`]), against 28 for the
//! traditional layout of Tang et al., table 1 ([`GBUFFER_BYTES_TRADITIONAL`]).

use crate::gpu::context::GpuContext;
use crate::gpu::transfer::texture_2d;

/// Bytes per pixel of the compressed G-buffer: RGBA8 diffuse + material id (4),
/// RGB10A2 normal + roughness (4), RGBA8 specular + model id (4), 32-bit depth (4).
pub const GBUFFER_BYTES_COMPRESSED: u32 = 16;
/// Bytes per pixel of the traditional layout of Tang et al., table 1: RGBA16 colour +
/// specular (8) + RGBA16 normal (8) + RGBA16 position (8) + 32-bit depth (4; the
/// paper's DEPTH24 occupies a 32-bit D24S8 texel).
pub const GBUFFER_BYTES_TRADITIONAL: u32 = 28;

pub(crate) const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgb10a2Unorm;
pub(crate) const SPECULAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub(crate) const LIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub(crate) const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A texture with its default view.
pub(crate) struct Target {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

pub(crate) struct Targets {
    pub width: u32,
    pub height: u32,
    pub depth: Target,
    pub albedo: Target,
    pub normal: Target,
    pub specular: Target,
    pub light_diffuse: Target,
    pub light_specular: Target,
    /// What the deferred geometry pass starts the specular light with
    /// (emission, ambient, environment) when the compute light pass adds the
    /// lights to it (it cannot read and write `light_specular` at once).
    pub emission: Target,
    pub scene: Target,
    pub aux: Vec<(String, Target)>,
    /// group 1 of the light pass: no light buffers bound.
    pub bg_light: wgpu::BindGroup,
    /// group 1 with everything (composition, resolve).
    pub bg_all: wgpu::BindGroup,
    /// group 1 of the light pre-pass final geometry pass: the light buffers.
    pub bg_final: wgpu::BindGroup,
    /// group 2 of the compute light pass: light buffers and scene written,
    /// emission read (deferred), or nothing read (light pre-pass).
    pub bg_compute_deferred: wgpu::BindGroup,
    pub bg_compute_prepass: wgpu::BindGroup,
    /// group 2 of the compute AUX resolve (AUX.depth, normal, position and
    /// motion written), where the adapter can store to them.
    pub bg_aux_compute: Option<wgpu::BindGroup>,
    /// group 2 of the compute AUX resolve's second half (AUX.albedo's raw
    /// twin, material and specular written), where the adapter can store to
    /// them.
    pub bg_aux_b_compute: Option<wgpu::BindGroup>,
    /// The raw `Rgba8Unorm` twin of AUX.albedo that the compute resolve stores
    /// (sRGB-encoded by the shader) and [`Targets::copy_aux_albedo`] copies
    /// into the published `Rgba8UnormSrgb` image (which readers get as a
    /// texture and view in its own format, so it stays sRGB).
    pub aux_albedo_store: Option<Target>,
}

/// The AUX images the compute resolve writes, by their index in the AUX list
/// (`published_aux`: depth, normal, position, ..., motion last).
const AUX_COMPUTE_IMAGES: [usize; 4] = [0, 1, 2, 6];

/// The AUX images the compute resolve's second half writes: albedo (through
/// its raw twin), material, specular.
const AUX_B_COMPUTE_IMAGES: [usize; 3] = [3, 4, 5];

/// Layouts of the group-1 bind groups.
pub(crate) struct TargetLayouts<'a> {
    /// depth, albedo, normal, specular, light diffuse, light specular.
    pub gbuffer: &'a wgpu::BindGroupLayout,
    /// light diffuse, light specular.
    pub light_buffers: &'a wgpu::BindGroupLayout,
    /// 1x1 Rgba16Float stand-in for the light buffers while they are targets.
    pub dummy_light: &'a wgpu::TextureView,
    /// The compute light pass's outputs and emission.
    pub light_compute: &'a wgpu::BindGroupLayout,
    /// The compute AUX resolve's outputs (`None`: the resolve is drawn).
    pub aux_compute: Option<&'a wgpu::BindGroupLayout>,
    /// The second half's outputs (`None`: that half is drawn).
    pub aux_b_compute: Option<&'a wgpu::BindGroupLayout>,
    /// The visibility buffer's resolve fills the G-buffer (`visibility.rs`):
    /// it stores to the normal, emission and specular light targets and
    /// copies into the albedo and specular ones.
    pub gbuffer_resolved: bool,
}

/// The frame's images, before their bind groups.
struct Images {
    depth: Target,
    albedo: Target,
    normal: Target,
    specular: Target,
    light_diffuse: Target,
    light_specular: Target,
    emission: Target,
    scene: Target,
    aux: Vec<(String, Target)>,
    aux_albedo_store: Option<Target>,
}

/// The bind groups of the frame's images.
struct Groups {
    light: wgpu::BindGroup,
    all: wgpu::BindGroup,
    prepass_final: wgpu::BindGroup,
    compute_deferred: wgpu::BindGroup,
    compute_prepass: wgpu::BindGroup,
    aux_compute: Option<wgpu::BindGroup>,
    aux_b_compute: Option<wgpu::BindGroup>,
}

/// Every image of a `width`×`height` frame (rendered to, sampled, copied; the
/// light buffers and the scene written by the compute light pass as well,
/// and the AUX images by the compute resolve's halves, `aux_storage`).
fn create_images(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    aux_formats: &[(String, wgpu::TextureFormat)],
    (aux_storage, resolved): ((bool, bool), bool),
) -> Images {
    let make_with = |label: &str, format: wgpu::TextureFormat, extra| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | extra;
        target(device, label, (width, height), format, usage)
    };
    let make = |label: &str, format| make_with(label, format, wgpu::TextureUsages::empty());
    // written by the compute light pass as well
    let storage =
        |label: &str| make_with(label, LIGHT_FORMAT, wgpu::TextureUsages::STORAGE_BINDING);
    // the visibility buffer's resolve stores or copies into the G-buffer
    let (stored, copied) = match resolved {
        true => (
            wgpu::TextureUsages::STORAGE_BINDING,
            wgpu::TextureUsages::COPY_DST,
        ),
        false => (wgpu::TextureUsages::empty(), wgpu::TextureUsages::empty()),
    };
    Images {
        depth: make("deferred depth", DEPTH_FORMAT),
        albedo: make_with("deferred G-buffer diffuse+material", ALBEDO_FORMAT, copied),
        normal: make_with("deferred G-buffer normal+roughness", NORMAL_FORMAT, stored),
        specular: make_with("deferred G-buffer specular+model", SPECULAR_FORMAT, copied),
        light_diffuse: storage("deferred light buffer diffuse"),
        light_specular: storage("deferred light buffer specular"),
        emission: make_with(
            "deferred emission, ambient and environment",
            LIGHT_FORMAT,
            stored,
        ),
        scene: storage("deferred scene (HDR)"),
        aux: aux_formats
            .iter()
            .enumerate()
            .map(|(i, (name, format))| {
                let label = format!("deferred aux {name}");
                let stored = (aux_storage.0 && AUX_COMPUTE_IMAGES.contains(&i))
                    || (aux_storage.1 && AUX_B_COMPUTE_IMAGES.contains(&i));
                let extra = match (stored, format.is_srgb()) {
                    (false, _) => wgpu::TextureUsages::empty(),
                    // stored through its raw twin, then copied in
                    (true, true) => wgpu::TextureUsages::COPY_DST,
                    (true, false) => wgpu::TextureUsages::STORAGE_BINDING,
                };
                (name.clone(), make_with(&label, *format, extra))
            })
            .collect(),
        aux_albedo_store: aux_storage.1.then(|| {
            let label = "deferred aux albedo (raw twin the compute resolve stores)";
            let format = aux_formats[AUX_B_COMPUTE_IMAGES[0]].1.remove_srgb_suffix();
            let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
            target(device, label, (width, height), format, usage)
        }),
    }
}

/// A texture of `size` in `format` with `usage`, and its view.
fn target(
    device: &wgpu::Device,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Target {
    let texture = device.create_texture(&texture_2d(label, size, format, usage, &[]));
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        ..Default::default()
    });
    Target { texture, view }
}

/// A bind group of `views`, bound 0, 1, 2… in order.
fn view_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    views: &[&wgpu::TextureView],
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &views
            .iter()
            .enumerate()
            .map(|(i, v)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: wgpu::BindingResource::TextureView(v),
            })
            .collect::<Vec<_>>(),
    })
}

/// The group-1 bind groups of the light pass (the light buffers stood in
/// for), of composition and resolve, and of the light pre-pass's final pass;
/// the compute light pass's group 2 for each technique.
fn create_groups(device: &wgpu::Device, im: &Images, layouts: &TargetLayouts) -> Groups {
    let group = |label: &str, layout: &wgpu::BindGroupLayout, views: &[&wgpu::TextureView]| {
        view_group(device, label, layout, views)
    };
    let light = group(
        "deferred group 1 (light pass)",
        layouts.gbuffer,
        &[
            &im.depth.view,
            &im.albedo.view,
            &im.normal.view,
            &im.specular.view,
            layouts.dummy_light,
            layouts.dummy_light,
        ],
    );
    let all = group(
        "deferred group 1 (composition, resolve)",
        layouts.gbuffer,
        &[
            &im.depth.view,
            &im.albedo.view,
            &im.normal.view,
            &im.specular.view,
            &im.light_diffuse.view,
            &im.light_specular.view,
        ],
    );
    let prepass_final = group(
        "deferred group 1 (light pre-pass final)",
        layouts.light_buffers,
        &[&im.light_diffuse.view, &im.light_specular.view],
    );
    let compute = |label: &str, read: &wgpu::TextureView| {
        group(
            label,
            layouts.light_compute,
            &[
                &im.light_diffuse.view,
                &im.light_specular.view,
                &im.scene.view,
                read,
            ],
        )
    };
    let aux_compute = layouts.aux_compute.map(|layout| {
        let views = AUX_COMPUTE_IMAGES.map(|i| &im.aux[i].1.view);
        let entries: Vec<wgpu::BindGroupEntry> = (4..)
            .zip(views)
            .map(|(binding, view)| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(view),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred group 2 (compute AUX resolve)"),
            layout,
            entries: &entries,
        })
    });
    let aux_b_compute = layouts.aux_b_compute.zip(im.aux_albedo_store.as_ref());
    let aux_b_compute = aux_b_compute.map(|(layout, albedo)| {
        let [_, material, specular] = AUX_B_COMPUTE_IMAGES.map(|i| &im.aux[i].1.view);
        let entries: Vec<wgpu::BindGroupEntry> = (8..)
            .zip([&albedo.view, material, specular])
            .map(|(binding, view)| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(view),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred group 2 (compute AUX resolve, albedo/material/specular)"),
            layout,
            entries: &entries,
        })
    });
    Groups {
        light,
        all,
        aux_compute,
        aux_b_compute,
        prepass_final,
        compute_deferred: compute(
            "deferred group 2 (compute lights, deferred)",
            &im.emission.view,
        ),
        compute_prepass: compute(
            "deferred group 2 (compute lights, light pre-pass)",
            layouts.dummy_light,
        ),
    }
}

impl Targets {
    /// Creates every target of a `width`×`height` frame.
    pub fn new(
        ctx: &GpuContext,
        width: u32,
        height: u32,
        aux_formats: &[(String, wgpu::TextureFormat)],
        layouts: &TargetLayouts,
    ) -> Result<Targets, crate::gpu::context::GpuError> {
        ctx.check_size(width, height, "deferred render target")?;
        ctx.scoped("deferred render targets", |device| {
            let aux_storage = (
                layouts.aux_compute.is_some(),
                layouts.aux_b_compute.is_some(),
            );
            let storage = (aux_storage, layouts.gbuffer_resolved);
            let images = create_images(device, (width, height), aux_formats, storage);
            let groups = create_groups(device, &images, layouts);
            let Images {
                depth,
                albedo,
                normal,
                specular,
                light_diffuse,
                light_specular,
                emission,
                scene,
                aux,
                aux_albedo_store,
            } = images;
            Targets {
                width,
                height,
                depth,
                albedo,
                normal,
                specular,
                light_diffuse,
                light_specular,
                emission,
                scene,
                aux,
                bg_light: groups.light,
                bg_all: groups.all,
                bg_final: groups.prepass_final,
                bg_compute_deferred: groups.compute_deferred,
                bg_compute_prepass: groups.compute_prepass,
                bg_aux_compute: groups.aux_compute,
                bg_aux_b_compute: groups.aux_b_compute,
                aux_albedo_store,
            }
        })
    }

    /// Copies the compute resolve's AUX.albedo (its raw twin, already
    /// sRGB-encoded) into the published sRGB image: the formats differ only
    /// in sRGB-ness, so the bytes are copied as they are.
    pub fn copy_aux_albedo(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(store) = &self.aux_albedo_store {
            let albedo = &self.aux[AUX_B_COMPUTE_IMAGES[0]].1.texture;
            encoder.copy_texture_to_texture(
                store.texture.as_image_copy(),
                albedo.as_image_copy(),
                store.texture.size(),
            );
        }
    }
}
