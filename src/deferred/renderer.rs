//! The GPU renderer: deferred shading with a compressed G-buffer and light volumes,
//! light pre-pass, and forward shading, all producing the same outputs.
//!
//! # G-buffer (seed 001, table 2)
//!
//! | target | format | content |
//! |---|---|---|
//! | albedo | `Rgba8UnormSrgb` | rgb base colour, a = material id / 255 (parameters in a storage buffer indexed by id, ≤ 256 materials) |
//! | normal | `Rgb10a2Unorm` | rg = view-space normal in two channels ([`NormalEncoding`], octahedral by default), b = specular `k_s`, a = 1 |
//! | depth | `Depth32Float` | hardware depth; view positions are reconstructed with the inverse projection |
//!
//! 12 bytes per pixel, against 28 for the traditional layout of seed 001 table 1 (see
//! [`GBUFFER_BYTES_COMPRESSED`], [`GBUFFER_BYTES_TRADITIONAL`]).
//!
//! # Frame (deferred)
//!
//! 1. Geometry pass: opaque and MASK objects into the G-buffer; the emission goes
//!    into the specular light buffer (`Rgba16Float`).
//! 2. Light pass, additive into two `Rgba16Float` light buffers (diffuse `f·L·(l·n)`,
//!    specular `f·k_s·L·(h·n)^α`, seed 001 eq. 8): ambient and directional lights
//!    as full-screen triangles; point lights as icosphere volumes and spot lights as
//!    cone volumes, culled against the view frustum on the CPU, all lights of a
//!    kind in one instanced draw. Volumes that hold the camera (or the near plane)
//!    are drawn as back faces with depth test `GREATER_EQUAL`, the others as front
//!    faces with `LESS`; a volume that holds the camera and crosses the far plane is
//!    drawn full-screen. The depth buffer is attached read-only while it is sampled.
//! 3. Composition: `albedo × diffuse + specular` (+ emission) into the HDR scene
//!    texture (`Rgba16Float`, linear); the background colour where nothing was drawn.
//! 4. Transparency: BLEND objects forward, sorted back to front, depth-tested (not
//!    written) against the deferred depth, lit by every visible light.
//! 5. Resolve: the G-buffer decoded into the `AUX.*` images.
//!
//! [`Technique::LightPrepass`] (seed 000) replaces 1–3 with a depth + normal pass, the
//! same light pass, and a second geometry pass reading the light buffers;
//! [`Technique::Forward`] shades every visible light per fragment in one pass.

use super::builtin;
use super::normal::NormalEncoding;
use super::scene::{AlphaMode, Camera, Light, LightKind, Scene, SceneError};
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use crate::gpu::executor::CameraStd;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};
use std::collections::HashMap;
use std::fmt;
use std::ops::Range;
use std::str::FromStr;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// Bytes per pixel of the compressed G-buffer: RGBA8 albedo+id (4) + RGB10A2
/// normal+specular (4) + 32-bit depth (4).
pub const GBUFFER_BYTES_COMPRESSED: u32 = 12;
/// Bytes per pixel of the traditional layout of seed 001 table 1: RGBA16 colour +
/// specular (8) + RGBA16 normal (8) + RGBA16 position (8) + 32-bit depth (4; the
/// paper's DEPTH24 occupies a 32-bit D24S8 texel).
pub const GBUFFER_BYTES_TRADITIONAL: u32 = 28;

const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgb10a2Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const LIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const SCENE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Errors of rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    /// Something about the request itself (size, texture too large, ...).
    #[error("{0}")]
    Invalid(String),
}

/// How a frame is shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Technique {
    /// Deferred shading with the compressed G-buffer and light volumes (seed 001).
    #[default]
    Deferred,
    /// Light pre-pass (seed 000): depth + normals, light buffer, final geometry pass.
    LightPrepass,
    /// Forward shading: every visible light per fragment.
    Forward,
}

impl Technique {
    pub const ALL: [Technique; 3] = [
        Technique::Deferred,
        Technique::LightPrepass,
        Technique::Forward,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Deferred => "deferred",
            Technique::LightPrepass => "light-prepass",
            Technique::Forward => "forward",
        }
    }
}

impl fmt::Display for Technique {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Technique {
    type Err = String;

    /// `deferred`, `light-prepass` (or `lpp`, `prepass`), `forward`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "deferred" => Ok(Technique::Deferred),
            "light-prepass" | "lightprepass" | "lpp" | "prepass" | "light-pre-pass" => {
                Ok(Technique::LightPrepass)
            }
            "forward" => Ok(Technique::Forward),
            other => Err(format!(
                "unknown renderer `{other}` (use deferred, light-prepass or forward)"
            )),
        }
    }
}

/// Options fixed when a [`Renderer`] is created.
#[derive(Debug, Clone)]
pub struct RendererOptions {
    /// How normals are stored in the G-buffer.
    pub normal_encoding: NormalEncoding,
    /// Generate mipmaps for scene textures (box filter).
    pub mipmaps: bool,
}

impl Default for RendererOptions {
    fn default() -> Self {
        RendererOptions {
            normal_encoding: NormalEncoding::default(),
            mipmaps: true,
        }
    }
}

/// The G-buffer and light buffers of the last frame (for inspection and
/// [`super::write_gbuffer`]).
#[derive(Debug, Clone)]
pub struct GBufferTextures {
    /// `Depth32Float` (0 near .. 1 far; 1 = no geometry).
    pub depth: wgpu::Texture,
    /// `Rgba8UnormSrgb`: albedo, a = material id / 255.
    pub albedo: wgpu::Texture,
    /// `Rgb10a2Unorm`: encoded normal (rg), specular (b).
    pub normal: wgpu::Texture,
    /// `Rgba16Float`: accumulated diffuse light (ambient included).
    pub light_diffuse: wgpu::Texture,
    /// `Rgba16Float`: accumulated specular light (deferred: plus emission).
    pub light_specular: wgpu::Texture,
}

/// What a frame produces. The textures belong to the [`Renderer`]: the next
/// `render` call of the same size draws into the same textures.
#[derive(Debug, Clone)]
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// `Rgba16Float`, linear HDR.
    pub scene: wgpu::Texture,
    /// The `AUX.*` images, named and formatted as
    /// [`crate::graph::plan::gbuffer_aux`]: `depth` R32Float linear view depth
    /// (`far` where nothing was drawn), `normal` Rgba16Float view-space normal (w = 1
    /// on geometry, 0 elsewhere), `position` Rgba16Float view-space position (w as
    /// for normal), `albedo` Rgba8UnormSrgb (a = coverage), `material` Rgba8Unorm
    /// (r = id / 255, g = log2(shininess) / 11, b = glTF roughness, a = glTF
    /// metallic), `specular` R16Float `k_s`. Usage: TEXTURE_BINDING | COPY_SRC |
    /// RENDER_ATTACHMENT.
    pub aux: Vec<(String, wgpu::Texture)>,
    pub camera: CameraStd,
    pub gbuffer: GBufferTextures,
}

impl RenderOutput {
    /// The aux image `name`.
    pub fn aux(&self, name: &str) -> Option<&wgpu::Texture> {
        self.aux.iter().find(|(n, _)| n == name).map(|(_, t)| t)
    }

    /// The aux images as `FrameInputs::aux` wants them.
    pub fn aux_map(&self) -> HashMap<String, &wgpu::Texture> {
        self.aux.iter().map(|(n, t)| (n.clone(), t)).collect()
    }
}

/// Statistics of one frame.
#[derive(Debug, Clone, Default)]
pub struct RenderStats {
    pub technique: Technique,
    pub width: u32,
    pub height: u32,
    /// Triangles submitted per geometry pass.
    pub triangles: usize,
    pub draw_calls: usize,
    pub lights_total: usize,
    /// Lights left after frustum culling (forward shades all of these per fragment).
    pub lights_visible: usize,
    /// Full-screen light passes (ambient, directional, volumes that hold the camera
    /// and cross the far plane).
    pub lights_fullscreen: usize,
    /// Volumes drawn as front faces (camera outside).
    pub volumes_outside: usize,
    /// Volumes drawn as back faces (camera inside).
    pub volumes_inside: usize,
    /// GPU milliseconds per pass (timestamp queries), when a timer was given.
    pub pass_ms: Vec<(String, f64)>,
    /// Sum of `pass_ms`.
    pub gpu_ms: Option<f64>,
    /// CPU milliseconds to prepare, encode and submit the frame.
    pub cpu_ms: f64,
    /// G-buffer bytes per pixel written by the technique's geometry pass(es):
    /// deferred 12 (albedo+id, normal+specular, depth), light pre-pass 12 (normal +
    /// specular, id, depth), forward 4 (depth; the albedo and normal targets it also
    /// fills only feed the aux images).
    pub gbuffer_bytes_per_pixel: u32,
}

/// Renders `scene` once (creating a [`Renderer`] for it). Use a [`Renderer`] to
/// render several frames without uploading the scene again.
pub fn render(
    ctx: &GpuContext,
    scene: &Scene,
    camera: &Camera,
    width: u32,
    height: u32,
    technique: Technique,
    timer: Option<&GpuTimer>,
) -> Result<(RenderOutput, RenderStats), RenderError> {
    let mut r = Renderer::new(ctx, scene, &RendererOptions::default())?;
    r.render(ctx, camera, width, height, technique, timer)
}

// ---------------------------------------------------------------- GPU structs

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    tangent: [f32; 4],
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuFrame {
    view: [f32; 16],
    proj: [f32; 16],
    inv_proj: [f32; 16],
    viewport: [f32; 4],
    background: [f32; 4],
    near: f32,
    far: f32,
    light_count: u32,
    _pad: u32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuMaterial {
    base_color: [f32; 4],
    emissive: [f32; 3],
    specular: f32,
    shininess: f32,
    alpha_cutoff: f32,
    normal_scale: f32,
    flags: u32,
    roughness: f32,
    metallic: f32,
    _pad: [f32; 2],
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct GpuInstance {
    model: [f32; 16],
    normal: [f32; 16],
    material: u32,
    _pad: [u32; 3],
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
struct GpuLight {
    position: [f32; 3],
    radius: f32,
    color: [f32; 3],
    kind: u32,
    direction: [f32; 3],
    volume_scale: f32,
    atten: [f32; 3],
    cos_outer: f32,
    cos_inner: f32,
    cone_radius: f32,
    volume: u32,
    _pad: u32,
}

const FLAG_MASK: u32 = 1;
const FLAG_BLEND: u32 = 2;
const FLAG_DOUBLE_SIDED: u32 = 4;
const FLAG_NORMAL_MAP: u32 = 8;

const KIND_AMBIENT: u32 = 0;
const KIND_DIRECTIONAL: u32 = 1;
const KIND_POINT: u32 = 2;
const KIND_SPOT: u32 = 3;

const VOLUME_FULLSCREEN: u32 = 0;
const VOLUME_SPHERE: u32 = 1;
const VOLUME_CONE: u32 = 2;

/// Segments of the cone proxy.
const CONE_SEGMENTS: u32 = 16;
/// Spot lights wider than this (half-angle) use a sphere volume.
const MAX_CONE_ANGLE: f32 = 1.40;

/// Face culling of a geometry pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Cull {
    /// Double-sided material.
    None,
    /// Back faces culled, counter-clockwise front (glTF).
    BackCcw,
    /// Back faces culled for a mirroring transform (negative determinant).
    BackCw,
}

impl Cull {
    fn primitive(self) -> wgpu::PrimitiveState {
        wgpu::PrimitiveState {
            cull_mode: match self {
                Cull::None => None,
                _ => Some(wgpu::Face::Back),
            },
            front_face: match self {
                Cull::BackCw => wgpu::FrontFace::Cw,
                _ => wgpu::FrontFace::Ccw,
            },
            ..Default::default()
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Pipe {
    GBuffer(Cull),
    Prepass(Cull),
    LppFinal(Cull),
    Forward(Cull),
    ForwardBlend(Cull),
    LightFullscreen,
    VolumeFront,
    VolumeBack,
    Compose,
    AuxA,
    AuxB,
}

/// An instanced draw of one mesh with one material.
#[derive(Debug, Clone)]
struct Batch {
    cull: Cull,
    material: usize,
    indices: Range<u32>,
    base_vertex: i32,
    instances: Range<u32>,
}

/// A transparent instance, sorted per frame.
#[derive(Debug, Clone)]
struct BlendItem {
    batch: Batch,
    center: Vec3,
}

struct Targets {
    width: u32,
    height: u32,
    depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
    albedo: wgpu::Texture,
    albedo_view: wgpu::TextureView,
    normal: wgpu::Texture,
    normal_view: wgpu::TextureView,
    diffuse: wgpu::Texture,
    diffuse_view: wgpu::TextureView,
    specular: wgpu::Texture,
    specular_view: wgpu::TextureView,
    scene: wgpu::Texture,
    scene_view: wgpu::TextureView,
    aux: Vec<(String, wgpu::Texture, wgpu::TextureView)>,
    /// group 1 for the light pass: no light buffers bound.
    bg_light: wgpu::BindGroup,
    /// group 1 with everything (composition, resolve).
    bg_all: wgpu::BindGroup,
    /// group 1 for the light pre-pass final pass: no albedo bound.
    bg_final: wgpu::BindGroup,
}

/// Per-frame light lists (indices into the GPU light array).
#[derive(Debug, Default)]
struct LightLists {
    gpu: Vec<GpuLight>,
    forward: Vec<u32>,
    fullscreen: Vec<u32>,
    sphere_out: Vec<u32>,
    sphere_in: Vec<u32>,
    cone_out: Vec<u32>,
    cone_in: Vec<u32>,
}

/// GPU resources of one scene; renders frames of any size, camera and technique.
pub struct Renderer {
    opts: RendererOptions,
    /// The auxiliary images' names and formats: `gbuffer_aux()`, except that depth is
    /// R16Float where R32Float cannot be rendered (GL on llvmpipe).
    aux_formats: Vec<(String, crate::script::types::Format)>,
    name: String,
    lights: Vec<Light>,
    background: Vec3,
    triangles: usize,
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    volume_vertices: wgpu::Buffer,
    volume_indices: wgpu::Buffer,
    sphere_indices: Range<u32>,
    cone_indices: Range<u32>,
    cone_base_vertex: i32,
    sphere_scale: f32,
    cone_poly_scale: f32,
    frame_buffer: wgpu::Buffer,
    material_buffer: wgpu::Buffer,
    instance_buffer: wgpu::Buffer,
    light_buffer: wgpu::Buffer,
    visible_buffer: wgpu::Buffer,
    g0_layout: wgpu::BindGroupLayout,
    g1_layout: wgpu::BindGroupLayout,
    g2_layout: wgpu::BindGroupLayout,
    g0: wgpu::BindGroup,
    material_groups: Vec<wgpu::BindGroup>,
    batches: Vec<Batch>,
    blend_items: Vec<BlendItem>,
    geometry_module: wgpu::ShaderModule,
    lighting_module: wgpu::ShaderModule,
    pipelines: HashMap<Pipe, wgpu::RenderPipeline>,
    dummy_rgba8: wgpu::TextureView,
    dummy_rgba16: wgpu::TextureView,
    targets: Option<Targets>,
    /// Pipelines created so far (for tests and logs).
    pub pipelines_created: usize,
}

fn storage_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

fn mat_array(m: Mat4) -> [f32; 16] {
    m.to_cols_array()
}

/// A box-filtered mip chain of RGBA8 data (level 0 first).
fn mip_chain(width: u32, height: u32, data: &[u8], levels: u32) -> Vec<(u32, u32, Vec<u8>)> {
    let mut out = vec![(width, height, data.to_vec())];
    for _ in 1..levels {
        let (pw, ph, prev) = out.last().expect("level 0 exists");
        let (w, h) = ((pw / 2).max(1), (ph / 2).max(1));
        let mut next = vec![0u8; (w * h * 4) as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..4 {
                    let mut sum = 0u32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (x * 2 + dx).min(pw - 1);
                        let sy = (y * 2 + dy).min(ph - 1);
                        sum += u32::from(prev[((sy * pw + sx) * 4 + c) as usize]);
                    }
                    next[((y * w + x) * 4 + c) as usize] = ((sum + 2) / 4) as u8;
                }
            }
        }
        out.push((w, h, next));
    }
    out
}

impl Renderer {
    /// Uploads `scene` (geometry, materials, textures) and compiles the shaders.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        opts: &RendererOptions,
    ) -> Result<Renderer, RenderError> {
        let start = Instant::now();
        if ctx.info.backend == wgpu::Backend::Gl {
            // Its shaders read the depth buffer with textureLoad, which naga cannot
            // translate to GLSL.
            return Err(RenderError::Gpu(GpuError::UnsupportedFormat {
                what: "the deferred renderer".into(),
                format: "Depth32Float read in shaders".into(),
                adapter: ctx.info.name.clone(),
                reason: "the GL backend cannot read depth textures in shaders; use Vulkan (software: apt-get install mesa-vulkan-drivers)".into(),
            }));
        }
        scene.validate()?;
        let device = &ctx.device;
        let name = scene.name.clone();

        // Geometry: one vertex and one index buffer for every mesh.
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::with_capacity(scene.meshes.len());
        for m in &scene.meshes {
            let base = vertices.len() as i32;
            let first = indices.len() as u32;
            for i in 0..m.positions.len() {
                let t = m
                    .tangents
                    .as_ref()
                    .and_then(|t| t.get(i).copied())
                    .unwrap_or(Vec4::ZERO);
                vertices.push(Vertex {
                    position: m.positions[i].into(),
                    normal: m.normals.get(i).copied().unwrap_or(Vec3::Y).into(),
                    uv: m.uvs.get(i).copied().unwrap_or_default().into(),
                    tangent: t.into(),
                });
            }
            if let Some(&bad) = m.indices.iter().find(|&&i| i as usize >= m.positions.len()) {
                return Err(RenderError::Invalid(format!(
                    "{name}: mesh `{}` has index {bad} >= {} vertices",
                    m.name,
                    m.positions.len()
                )));
            }
            indices.extend_from_slice(&m.indices);
            ranges.push((base, first..indices.len() as u32));
        }

        // Instances: sorted so that runs of (cull, material, mesh) become batches.
        let cull_of = |inst: &super::scene::Instance| -> Cull {
            let mat = &scene.materials[inst.material];
            if mat.double_sided {
                Cull::None
            } else if inst.transform.determinant() < 0.0 {
                Cull::BackCw
            } else {
                Cull::BackCcw
            }
        };
        for inst in &scene.instances {
            if inst.mesh >= scene.meshes.len() || inst.material >= scene.materials.len() {
                return Err(RenderError::Invalid(format!(
                    "{name}: instance `{}` refers to a missing mesh or material",
                    inst.name
                )));
            }
        }
        let mut order: Vec<usize> = (0..scene.instances.len()).collect();
        order.sort_by_key(|&i| {
            let inst = &scene.instances[i];
            let blend = scene.materials[inst.material].alpha_mode == AlphaMode::Blend;
            (blend, cull_of(inst), inst.material, inst.mesh)
        });
        let mut gpu_instances = Vec::with_capacity(order.len());
        let mut batches: Vec<Batch> = Vec::new();
        let mut blend_items = Vec::new();
        let mesh_bounds: Vec<_> = scene.meshes.iter().map(|m| m.bounds()).collect();
        for (slot, &i) in order.iter().enumerate() {
            let inst = &scene.instances[i];
            let model = inst.transform;
            gpu_instances.push(GpuInstance {
                model: mat_array(model),
                normal: mat_array(model.inverse().transpose()),
                material: inst.material as u32,
                _pad: [0; 3],
            });
            let (base_vertex, ref idx) = ranges[inst.mesh];
            let batch = Batch {
                cull: cull_of(inst),
                material: inst.material,
                indices: idx.clone(),
                base_vertex,
                instances: slot as u32..slot as u32 + 1,
            };
            if batch.indices.is_empty() {
                continue;
            }
            if scene.materials[inst.material].alpha_mode == AlphaMode::Blend {
                blend_items.push(BlendItem {
                    batch,
                    center: mesh_bounds[inst.mesh].transformed(&model).center(),
                });
                continue;
            }
            match batches.last_mut() {
                Some(last)
                    if last.cull == batch.cull
                        && last.material == batch.material
                        && last.indices == batch.indices
                        && last.base_vertex == batch.base_vertex
                        && last.instances.end == slot as u32 =>
                {
                    last.instances.end += 1;
                }
                _ => batches.push(batch),
            }
        }

        let gpu_materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| {
                let mut flags = 0;
                match m.alpha_mode {
                    AlphaMode::Mask => flags |= FLAG_MASK,
                    AlphaMode::Blend => flags |= FLAG_BLEND,
                    AlphaMode::Opaque => {}
                }
                if m.double_sided {
                    flags |= FLAG_DOUBLE_SIDED;
                }
                if m.surface.texture("normal_map").is_some() {
                    flags |= FLAG_NORMAL_MAP;
                }
                // Transitional: the fixed Blinn-Phong pipeline reads the standard
                // surface's factors.
                let base = m.surface_param("base_color", [1.0; 4]);
                let emissive = m.surface_param("emissive", [0.0; 4]);
                let spec = m.surface_param("specular", [0.04; 4]);
                let roughness = m.surface_param("roughness", [0.5; 4])[0];
                let metallic = m.surface_param("metallic", [0.0; 4])[0];
                let shininess = m
                    .lighting
                    .param("specular_power")
                    .or(m.lighting.param("shininess"))
                    .map(|v| v[0] as f32)
                    .unwrap_or_else(|| {
                        let r = roughness.max(0.03);
                        (2.0 / (r * r * r * r) - 2.0).clamp(1.0, 2048.0)
                    });
                GpuMaterial {
                    base_color: base,
                    emissive: [emissive[0], emissive[1], emissive[2]],
                    specular: spec[0] * (1.0 - metallic) + metallic,
                    shininess: shininess.max(1.0),
                    alpha_cutoff: m.alpha_cutoff,
                    normal_scale: m.surface_param("normal_scale", [1.0; 4])[0],
                    flags,
                    roughness,
                    metallic,
                    _pad: [0.0; 2],
                }
            })
            .collect();

        // Light volume proxies.
        let sphere = builtin::icosphere(2);
        let cone = builtin::cone(CONE_SEGMENTS);
        let sphere_scale = 1.0 / builtin::inradius(&sphere);
        let cone_poly_scale = 1.0 / (std::f32::consts::PI / CONE_SEGMENTS as f32).cos();
        let mut vol_v: Vec<[f32; 3]> = sphere.positions.iter().map(|p| (*p).into()).collect();
        let cone_base_vertex = vol_v.len() as i32;
        vol_v.extend(cone.positions.iter().map(|p| <[f32; 3]>::from(*p)));
        let mut vol_i = sphere.indices.clone();
        let sphere_indices = 0..vol_i.len() as u32;
        vol_i.extend_from_slice(&cone.indices);
        let cone_indices = sphere_indices.end..vol_i.len() as u32;

        let max_dim = device.limits().max_texture_dimension_2d;
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

        let prelude = format!(
            "const NORMAL_ENCODING: u32 = {}u;\n{}\n",
            opts.normal_encoding.shader_id(),
            include_str!("common.wgsl")
        );
        let geometry_src = format!(
            "{prelude}{}\n{}",
            include_str!("gbuffer_read.wgsl"),
            include_str!("geometry.wgsl")
        );
        let lighting_src = format!(
            "{prelude}{}\n{}",
            include_str!("gbuffer_read.wgsl"),
            include_str!("lighting.wgsl")
        );

        let built = ctx.scoped("deferred renderer: scene upload", |device| {
            let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
            };
            let vertex_buffer = init(
                "deferred vertices",
                bytemuck::cast_slice(&vertices),
                wgpu::BufferUsages::VERTEX,
            );
            let index_buffer = init(
                "deferred indices",
                bytemuck::cast_slice(&indices),
                wgpu::BufferUsages::INDEX,
            );
            let volume_vertices = init(
                "deferred light volume vertices",
                bytemuck::cast_slice(&vol_v),
                wgpu::BufferUsages::VERTEX,
            );
            let volume_indices = init(
                "deferred light volume indices",
                bytemuck::cast_slice(&vol_i),
                wgpu::BufferUsages::INDEX,
            );
            let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("deferred frame uniforms"),
                size: std::mem::size_of::<GpuFrame>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut mats = gpu_materials.clone();
            if mats.is_empty() {
                mats.push(GpuMaterial::zeroed());
            }
            let material_buffer = init(
                "deferred materials",
                bytemuck::cast_slice(&mats),
                wgpu::BufferUsages::STORAGE,
            );
            let mut insts = gpu_instances.clone();
            if insts.is_empty() {
                insts.push(GpuInstance::zeroed());
            }
            let instance_buffer = init(
                "deferred instances",
                bytemuck::cast_slice(&insts),
                wgpu::BufferUsages::STORAGE,
            );
            let geometry_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("deferred geometry shaders"),
                source: wgpu::ShaderSource::Wgsl(geometry_src.into()),
            });
            let lighting_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("deferred lighting shaders"),
                source: wgpu::ShaderSource::Wgsl(lighting_src.into()),
            });
            let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
            let g0_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("deferred group 0 (frame, materials, instances, lights)"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: vf,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    storage_entry(1, vf),
                    storage_entry(2, vf),
                    storage_entry(3, vf),
                    storage_entry(4, vf),
                ],
            });
            let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
            let g1_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("deferred group 1 (G-buffer)"),
                entries: &[
                    texture_entry(0, wgpu::TextureSampleType::Depth),
                    texture_entry(1, unfilterable),
                    texture_entry(2, unfilterable),
                    texture_entry(3, unfilterable),
                    texture_entry(4, unfilterable),
                ],
            });
            let filterable = wgpu::TextureSampleType::Float { filterable: true };
            let g2_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("deferred group 2 (material textures)"),
                entries: &[
                    texture_entry(0, filterable),
                    texture_entry(1, filterable),
                    texture_entry(2, filterable),
                    wgpu::BindGroupLayoutEntry {
                        binding: 3,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                        count: None,
                    },
                ],
            });
            (
                vertex_buffer,
                index_buffer,
                volume_vertices,
                volume_indices,
                frame_buffer,
                material_buffer,
                instance_buffer,
                geometry_module,
                lighting_module,
                g0_layout,
                g1_layout,
                g2_layout,
            )
        })?;
        let (
            vertex_buffer,
            index_buffer,
            volume_vertices,
            volume_indices,
            frame_buffer,
            material_buffer,
            instance_buffer,
            geometry_module,
            lighting_module,
            g0_layout,
            g1_layout,
            g2_layout,
        ) = built;

        // Textures (each image once per colour space) and material bind groups.
        let mut gpu_textures: HashMap<(usize, bool), wgpu::TextureView> = HashMap::new();
        let mut texture_view =
            |index: usize, srgb: bool| -> Result<wgpu::TextureView, RenderError> {
                if let Some(v) = gpu_textures.get(&(index, srgb)) {
                    return Ok(v.clone());
                }
                let t = &scene.textures[index];
                let levels = if opts.mipmaps {
                    32 - t.width.max(t.height).leading_zeros()
                } else {
                    1
                };
                let format = if srgb {
                    wgpu::TextureFormat::Rgba8UnormSrgb
                } else {
                    wgpu::TextureFormat::Rgba8Unorm
                };
                let label = format!(
                    "deferred texture {} ({})",
                    t.name,
                    if srgb { "sRGB" } else { "linear" }
                );
                let view = ctx.scoped(&label, |device| {
                    let texture = device.create_texture(&wgpu::TextureDescriptor {
                        label: Some(&label),
                        size: wgpu::Extent3d {
                            width: t.width,
                            height: t.height,
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: levels,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                        view_formats: &[],
                    });
                    for (level, (w, h, data)) in mip_chain(t.width, t.height, &t.rgba8, levels)
                        .iter()
                        .enumerate()
                    {
                        ctx.queue.write_texture(
                            wgpu::TexelCopyTextureInfo {
                                texture: &texture,
                                mip_level: level as u32,
                                origin: wgpu::Origin3d::ZERO,
                                aspect: wgpu::TextureAspect::All,
                            },
                            data,
                            wgpu::TexelCopyBufferLayout {
                                offset: 0,
                                bytes_per_row: Some(w * 4),
                                rows_per_image: Some(*h),
                            },
                            wgpu::Extent3d {
                                width: *w,
                                height: *h,
                                depth_or_array_layers: 1,
                            },
                        );
                    }
                    texture.create_view(&wgpu::TextureViewDescriptor {
                        label: Some(&label),
                        ..Default::default()
                    })
                })?;
                gpu_textures.insert((index, srgb), view.clone());
                Ok(view)
            };
        // 1x1 textures: defaults for missing material maps and placeholders.
        let one_texel = |label: &str,
                         format: wgpu::TextureFormat,
                         texel: &[u8]|
         -> Result<wgpu::TextureView, GpuError> {
            Ok(ctx
                .upload_texture(label, 1, 1, format, texel, wgpu::TextureUsages::empty())?
                .create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("{label} view")),
                    ..Default::default()
                }))
        };
        let white = one_texel(
            "deferred default white texture",
            wgpu::TextureFormat::Rgba8UnormSrgb,
            &[255, 255, 255, 255],
        )?;
        let flat = one_texel(
            "deferred default flat normal texture",
            wgpu::TextureFormat::Rgba8Unorm,
            &[128, 128, 255, 255],
        )?;
        let dummy_rgba8 = one_texel(
            "deferred dummy rgba8",
            wgpu::TextureFormat::Rgba8Unorm,
            &[0, 0, 0, 0],
        )?;
        let dummy_rgba16 = one_texel(
            "deferred dummy rgba16f",
            wgpu::TextureFormat::Rgba16Float,
            &[0; 8],
        )?;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("deferred material sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let mut material_groups = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            let base = match m.surface.texture("base_color_map") {
                Some(i) => texture_view(i, true)?,
                None => white.clone(),
            };
            let normal = match m.surface.texture("normal_map") {
                Some(i) => texture_view(i, false)?,
                None => flat.clone(),
            };
            let emissive = match m.surface.texture("emissive_map") {
                Some(i) => texture_view(i, true)?,
                None => white.clone(),
            };
            let label = format!("deferred material {}", m.name);
            material_groups.push(ctx.scoped(&label, |device| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&label),
                    layout: &g2_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: wgpu::BindingResource::TextureView(&base),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&normal),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(&emissive),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: wgpu::BindingResource::Sampler(&sampler),
                        },
                    ],
                })
            })?);
        }

        let (light_buffer, visible_buffer) = Self::light_buffers(device, 64, 64 * 6);
        let g0 = Self::make_g0(
            device,
            &g0_layout,
            &frame_buffer,
            &material_buffer,
            &instance_buffer,
            &light_buffer,
            &visible_buffer,
        );
        let triangles = scene.triangle_count();
        log::info!(
            "{name}: renderer ready in {:.1} ms: {} vertices, {} triangles, {} opaque batches, {} transparent instances, {} materials, {} textures",
            start.elapsed().as_secs_f64() * 1e3,
            vertices.len(),
            triangles,
            batches.len(),
            blend_items.len(),
            scene.materials.len(),
            gpu_textures.len()
        );
        let depth_renderable = ctx.format_support(wgpu::TextureFormat::R32Float).render;
        if !depth_renderable {
            log::warn!(
                "this adapter cannot render to R32Float: AUX.depth is R16Float (half precision)"
            );
        }
        let aux_formats = crate::graph::plan::gbuffer_aux()
            .into_iter()
            .map(|(n, f)| match (n.as_str(), depth_renderable) {
                ("depth", false) => (n, crate::script::types::Format::R16f),
                _ => (n, f),
            })
            .collect();
        Ok(Renderer {
            aux_formats,
            opts: opts.clone(),
            name,
            lights: scene.lights.clone(),
            background: scene.background,
            triangles,
            vertex_buffer,
            index_buffer,
            volume_vertices,
            volume_indices,
            sphere_indices,
            cone_indices,
            cone_base_vertex,
            sphere_scale,
            cone_poly_scale,
            frame_buffer,
            material_buffer,
            instance_buffer,
            light_buffer,
            visible_buffer,
            g0_layout,
            g1_layout,
            g2_layout,
            g0,
            material_groups,
            batches,
            blend_items,
            geometry_module,
            lighting_module,
            pipelines: HashMap::new(),
            dummy_rgba8,
            dummy_rgba16,
            targets: None,
            pipelines_created: 0,
        })
    }

    /// The lights rendered (the scene's, or those given to [`Renderer::set_lights`]).
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Replaces the lights without uploading the scene again.
    pub fn set_lights(&mut self, lights: Vec<Light>) {
        self.lights = lights;
    }

    /// The options the renderer was created with.
    pub fn options(&self) -> &RendererOptions {
        &self.opts
    }

    fn light_buffers(
        device: &wgpu::Device,
        lights: usize,
        indices: usize,
    ) -> (wgpu::Buffer, wgpu::Buffer) {
        let light_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("deferred lights"),
            size: (lights.max(1) * std::mem::size_of::<GpuLight>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let visible_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("deferred visible light indices"),
            size: (indices.max(4) * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (light_buffer, visible_buffer)
    }

    fn make_g0(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
        materials: &wgpu::Buffer,
        instances: &wgpu::Buffer,
        lights: &wgpu::Buffer,
        visible: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deferred group 0"),
            layout,
            entries: &[frame, materials, instances, lights, visible]
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: b.as_entire_binding(),
                })
                .collect::<Vec<_>>(),
        })
    }

    /// Creates the pipeline `which` if needed.
    fn ensure_pipeline(&mut self, ctx: &GpuContext, which: Pipe) -> Result<(), RenderError> {
        if self.pipelines.contains_key(&which) {
            return Ok(());
        }
        let label = format!("deferred pipeline {which:?}");
        let blend_add = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        };
        let target = |format: wgpu::TextureFormat| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let additive = |format: wgpu::TextureFormat| {
            Some(wgpu::ColorTargetState {
                format,
                blend: Some(blend_add),
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let depth = |write: bool, compare: wgpu::CompareFunction| wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(write),
            depth_compare: Some(compare),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        };
        let vertex_attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4];
        let geometry_vb = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vertex_attrs,
        })];
        let volume_attrs = wgpu::vertex_attr_array![0 => Float32x3];
        let volume_vb = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &volume_attrs,
        })];
        use wgpu::CompareFunction as C;
        use wgpu::TextureFormat as F;
        // (module, vs, fs, vertex buffers, targets, depth, primitive, groups)
        let geo = &self.geometry_module;
        let lit = &self.lighting_module;
        let groups_geo: [Option<&wgpu::BindGroupLayout>; 3] =
            [Some(&self.g0_layout), None, Some(&self.g2_layout)];
        let groups_all: [Option<&wgpu::BindGroupLayout>; 3] = [
            Some(&self.g0_layout),
            Some(&self.g1_layout),
            Some(&self.g2_layout),
        ];
        let groups_light: [Option<&wgpu::BindGroupLayout>; 2] =
            [Some(&self.g0_layout), Some(&self.g1_layout)];
        #[allow(clippy::type_complexity)]
        let (module, vs, fs, buffers, targets, depth_state, primitive, groups): (
            &wgpu::ShaderModule,
            &str,
            &str,
            &[Option<wgpu::VertexBufferLayout>],
            Vec<Option<wgpu::ColorTargetState>>,
            Option<wgpu::DepthStencilState>,
            wgpu::PrimitiveState,
            &[Option<&wgpu::BindGroupLayout>],
        ) = match which {
            Pipe::GBuffer(cull) => (
                geo,
                "vs_geometry",
                "fs_gbuffer",
                &geometry_vb,
                vec![
                    target(ALBEDO_FORMAT),
                    target(NORMAL_FORMAT),
                    target(LIGHT_FORMAT),
                ],
                Some(depth(true, C::Less)),
                cull.primitive(),
                &groups_geo,
            ),
            Pipe::Prepass(cull) => (
                geo,
                "vs_geometry",
                "fs_prepass",
                &geometry_vb,
                vec![
                    Some(wgpu::ColorTargetState {
                        format: ALBEDO_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALPHA,
                    }),
                    target(NORMAL_FORMAT),
                ],
                Some(depth(true, C::Less)),
                cull.primitive(),
                &groups_geo,
            ),
            Pipe::LppFinal(cull) => (
                geo,
                "vs_geometry",
                "fs_lpp_final",
                &geometry_vb,
                vec![target(SCENE_FORMAT), target(ALBEDO_FORMAT)],
                Some(depth(false, C::LessEqual)),
                cull.primitive(),
                &groups_all,
            ),
            Pipe::Forward(cull) => (
                geo,
                "vs_geometry",
                "fs_forward",
                &geometry_vb,
                vec![
                    target(SCENE_FORMAT),
                    target(ALBEDO_FORMAT),
                    target(NORMAL_FORMAT),
                ],
                Some(depth(true, C::Less)),
                cull.primitive(),
                &groups_geo,
            ),
            Pipe::ForwardBlend(cull) => (
                geo,
                "vs_geometry",
                "fs_forward_blend",
                &geometry_vb,
                vec![Some(wgpu::ColorTargetState {
                    format: SCENE_FORMAT,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::COLOR,
                })],
                Some(depth(false, C::Less)),
                cull.primitive(),
                &groups_geo,
            ),
            Pipe::LightFullscreen => (
                lit,
                "vs_light_fullscreen",
                "fs_light",
                &[],
                vec![additive(LIGHT_FORMAT), additive(LIGHT_FORMAT)],
                Some(depth(false, C::Always)),
                wgpu::PrimitiveState::default(),
                &groups_light,
            ),
            Pipe::VolumeFront => (
                lit,
                "vs_volume",
                "fs_light",
                &volume_vb,
                vec![additive(LIGHT_FORMAT), additive(LIGHT_FORMAT)],
                Some(depth(false, C::Less)),
                Cull::BackCcw.primitive(),
                &groups_light,
            ),
            Pipe::VolumeBack => (
                lit,
                "vs_volume",
                "fs_light",
                &volume_vb,
                vec![additive(LIGHT_FORMAT), additive(LIGHT_FORMAT)],
                Some(depth(false, C::GreaterEqual)),
                wgpu::PrimitiveState {
                    cull_mode: Some(wgpu::Face::Front),
                    ..Default::default()
                },
                &groups_light,
            ),
            Pipe::Compose => (
                lit,
                "vs_fullscreen",
                "fs_compose",
                &[],
                vec![target(SCENE_FORMAT)],
                None,
                wgpu::PrimitiveState::default(),
                &groups_light,
            ),
            Pipe::AuxA => (
                lit,
                "vs_fullscreen",
                "fs_aux_a",
                &[],
                vec![
                    target(crate::gpu::executor::wgpu_format(self.aux_format("depth"))),
                    target(F::Rgba16Float),
                    target(F::Rgba16Float),
                ],
                None,
                wgpu::PrimitiveState::default(),
                &groups_light,
            ),
            Pipe::AuxB => (
                lit,
                "vs_fullscreen",
                "fs_aux_b",
                &[],
                vec![
                    target(F::Rgba8UnormSrgb),
                    target(F::Rgba8Unorm),
                    target(F::R16Float),
                ],
                None,
                wgpu::PrimitiveState::default(),
                &groups_light,
            ),
        };
        let pipeline = ctx.scoped(&label, |device| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&label),
                bind_group_layouts: groups,
                immediate_size: 0,
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive,
                depth_stencil: depth_state,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        self.pipelines_created += 1;
        self.pipelines.insert(which, pipeline);
        Ok(())
    }

    /// The auxiliary images this renderer produces, with their formats (plan effects
    /// with these).
    pub fn aux_formats(&self) -> &[(String, crate::script::types::Format)] {
        &self.aux_formats
    }

    fn aux_format(&self, name: &str) -> crate::script::types::Format {
        self.aux_formats
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, f)| *f)
            .expect("known aux image")
    }

    fn pipeline(&self, which: Pipe) -> &wgpu::RenderPipeline {
        &self.pipelines[&which]
    }

    /// Creates the frame targets for `width`×`height` if the size changed.
    fn ensure_targets(
        &mut self,
        ctx: &GpuContext,
        width: u32,
        height: u32,
    ) -> Result<(), RenderError> {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| t.width == width && t.height == height)
        {
            return Ok(());
        }
        ctx.check_size(width, height, "deferred render target")?;
        let targets = ctx.scoped("deferred render targets", |device| {
            let make = |label: &str, format: wgpu::TextureFormat| {
                let texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width,
                        height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                let view = texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(label),
                    ..Default::default()
                });
                (texture, view)
            };
            let (depth, depth_view) = make("deferred depth", DEPTH_FORMAT);
            let (albedo, albedo_view) = make("deferred G-buffer albedo+id", ALBEDO_FORMAT);
            let (normal, normal_view) = make("deferred G-buffer normal+specular", NORMAL_FORMAT);
            let (diffuse, diffuse_view) = make("deferred light buffer diffuse", LIGHT_FORMAT);
            let (specular, specular_view) = make("deferred light buffer specular", LIGHT_FORMAT);
            let (scene, scene_view) = make("deferred scene (HDR)", SCENE_FORMAT);
            let aux = self
                .aux_formats
                .clone()
                .into_iter()
                .map(|(name, format)| {
                    let (t, v) = make(
                        &format!("deferred aux {name}"),
                        crate::gpu::executor::wgpu_format(format),
                    );
                    (name, t, v)
                })
                .collect();
            let group = |label: &str, views: [&wgpu::TextureView; 5]| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(label),
                    layout: &self.g1_layout,
                    entries: &views
                        .iter()
                        .enumerate()
                        .map(|(i, v)| wgpu::BindGroupEntry {
                            binding: i as u32,
                            resource: wgpu::BindingResource::TextureView(v),
                        })
                        .collect::<Vec<_>>(),
                })
            };
            let bg_light = group(
                "deferred group 1 (light pass)",
                [
                    &depth_view,
                    &albedo_view,
                    &normal_view,
                    &self.dummy_rgba16,
                    &self.dummy_rgba16,
                ],
            );
            let bg_all = group(
                "deferred group 1 (composition)",
                [
                    &depth_view,
                    &albedo_view,
                    &normal_view,
                    &diffuse_view,
                    &specular_view,
                ],
            );
            let bg_final = group(
                "deferred group 1 (light pre-pass final)",
                [
                    &depth_view,
                    &self.dummy_rgba8,
                    &normal_view,
                    &diffuse_view,
                    &specular_view,
                ],
            );
            Targets {
                width,
                height,
                depth,
                depth_view,
                albedo,
                albedo_view,
                normal,
                normal_view,
                diffuse,
                diffuse_view,
                specular,
                specular_view,
                scene,
                scene_view,
                aux,
                bg_light,
                bg_all,
                bg_final,
            }
        })?;
        self.targets = Some(targets);
        Ok(())
    }

    /// Frustum culling and volume classification of the lights for one frame.
    fn classify_lights(
        &self,
        camera: &Camera,
        view: &Mat4,
        proj: &Mat4,
        aspect: f32,
    ) -> LightLists {
        let mut lists = LightLists::default();
        let planes = frustum_planes(proj);
        let half_fov = (camera.fov_y * 0.5).tan();
        // distance from the eye to a corner of the near plane rectangle
        let near_margin =
            camera.near * (1.0 + half_fov * half_fov * (1.0 + aspect * aspect)).sqrt();
        for l in &self.lights {
            let color = l.color * l.intensity;
            if color.max_element() <= 0.0 || !color.is_finite() {
                continue;
            }
            let dir_view = view
                .transform_vector3(l.direction)
                .normalize_or(Vec3::NEG_Z);
            let mut g = GpuLight {
                position: [0.0; 3],
                radius: 0.0,
                color: color.into(),
                kind: KIND_AMBIENT,
                direction: dir_view.into(),
                volume_scale: 1.0,
                atten: l.attenuation,
                cos_outer: -1.0,
                cos_inner: 1.0,
                cone_radius: 0.0,
                volume: VOLUME_FULLSCREEN,
                _pad: 0,
            };
            let index = lists.gpu.len() as u32;
            match l.kind {
                LightKind::Ambient | LightKind::Directional => {
                    g.kind = if l.kind == LightKind::Ambient {
                        KIND_AMBIENT
                    } else {
                        KIND_DIRECTIONAL
                    };
                    lists.gpu.push(g);
                    lists.forward.push(index);
                    lists.fullscreen.push(index);
                }
                LightKind::Point | LightKind::Spot { .. } => {
                    let radius = l.radius();
                    if radius.is_nan() || radius <= 0.0 {
                        continue;
                    }
                    let radius = radius.min(1e7);
                    let pos = view.transform_point3(l.position);
                    g.position = pos.into();
                    g.radius = radius;
                    // bounding sphere of the lit region (for culling) and of the proxy
                    let (mut cull_center, mut cull_radius) = (pos, radius);
                    let (proxy_center, proxy_radius);
                    if let LightKind::Spot { inner, outer } = l.kind {
                        let outer = outer.clamp(1e-3, std::f32::consts::FRAC_PI_2);
                        let inner = inner.clamp(0.0, outer);
                        g.kind = KIND_SPOT;
                        g.cos_outer = outer.cos();
                        g.cos_inner = inner.cos().max(g.cos_outer + 1e-4);
                        if outer <= MAX_CONE_ANGLE {
                            g.volume = VOLUME_CONE;
                            g.cone_radius = radius * outer.tan() * self.cone_poly_scale;
                            let (c, r) =
                                cone_bounding_sphere(pos, dir_view, radius, radius * outer.tan());
                            if r < cull_radius {
                                cull_center = c;
                                cull_radius = r;
                            }
                            let (pc, pr) =
                                cone_bounding_sphere(pos, dir_view, radius, g.cone_radius);
                            proxy_center = pc;
                            proxy_radius = pr;
                        } else {
                            g.volume = VOLUME_SPHERE;
                            g.volume_scale = self.sphere_scale;
                            proxy_center = pos;
                            proxy_radius = radius * self.sphere_scale;
                        }
                    } else {
                        g.kind = KIND_POINT;
                        g.volume = VOLUME_SPHERE;
                        g.volume_scale = self.sphere_scale;
                        proxy_center = pos;
                        proxy_radius = radius * self.sphere_scale;
                    }
                    let outside = planes
                        .iter()
                        .any(|p| p.truncate().dot(cull_center) + p.w < -cull_radius);
                    if outside {
                        continue;
                    }
                    let inside = proxy_center.length() < proxy_radius + near_margin;
                    let crosses_far = -proxy_center.z + proxy_radius > camera.far * 0.999;
                    lists.gpu.push(g);
                    lists.forward.push(index);
                    let list = match (inside, crosses_far, g.volume) {
                        (true, true, _) => &mut lists.fullscreen,
                        (true, false, VOLUME_CONE) => &mut lists.cone_in,
                        (true, false, _) => &mut lists.sphere_in,
                        (false, _, VOLUME_CONE) => &mut lists.cone_out,
                        (false, _, _) => &mut lists.sphere_out,
                    };
                    list.push(index);
                }
            }
        }
        lists
    }

    /// Renders one frame.
    ///
    /// With a `timer` (see [`GpuTimer::new`]; 16 passes are enough) the GPU time of
    /// every pass is measured and returned in [`RenderStats::pass_ms`].
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        width: u32,
        height: u32,
        technique: Technique,
        timer: Option<&GpuTimer>,
    ) -> Result<(RenderOutput, RenderStats), RenderError> {
        let start = Instant::now();
        if !(camera.near > 0.0
            && camera.far > camera.near
            && camera.fov_y > 0.0
            && camera.fov_y < std::f32::consts::PI)
        {
            return Err(RenderError::Invalid(format!(
                "invalid camera ({camera}): need 0 < near < far and 0 < fov < 180°"
            )));
        }
        self.ensure_targets(ctx, width, height)?;
        let cull_variants = [Cull::None, Cull::BackCcw, Cull::BackCw];
        let mut needed = vec![Pipe::AuxA, Pipe::AuxB];
        for c in cull_variants {
            if self.batches.iter().any(|b| b.cull == c) {
                match technique {
                    Technique::Deferred => needed.push(Pipe::GBuffer(c)),
                    Technique::LightPrepass => {
                        needed.push(Pipe::Prepass(c));
                        needed.push(Pipe::LppFinal(c));
                    }
                    Technique::Forward => needed.push(Pipe::Forward(c)),
                }
            }
            if self.blend_items.iter().any(|b| b.batch.cull == c) {
                needed.push(Pipe::ForwardBlend(c));
            }
        }
        if technique != Technique::Forward {
            needed.extend([Pipe::LightFullscreen, Pipe::VolumeFront, Pipe::VolumeBack]);
        }
        if technique == Technique::Deferred {
            needed.push(Pipe::Compose);
        }
        for p in needed {
            self.ensure_pipeline(ctx, p)?;
        }

        let aspect = width as f32 / height as f32;
        let view = camera.view();
        let proj = camera.proj(aspect);
        let lists = self.classify_lights(camera, &view, &proj, aspect);

        // Upload per-frame data.
        let mut visible: Vec<u32> = Vec::new();
        let mut range = |list: &[u32]| -> Range<u32> {
            let start = visible.len() as u32;
            visible.extend_from_slice(list);
            start..visible.len() as u32
        };
        let forward_range = range(&lists.forward);
        let fullscreen_range = range(&lists.fullscreen);
        let sphere_out = range(&lists.sphere_out);
        let sphere_in = range(&lists.sphere_in);
        let cone_out = range(&lists.cone_out);
        let cone_in = range(&lists.cone_in);
        debug_assert_eq!(forward_range.start, 0);
        let light_bytes = (lists.gpu.len() * std::mem::size_of::<GpuLight>()) as u64;
        if light_bytes > self.light_buffer.size()
            || (visible.len() * 4) as u64 > self.visible_buffer.size()
        {
            let (lb, vb) = Self::light_buffers(
                &ctx.device,
                lists.gpu.len().next_power_of_two(),
                visible.len().next_power_of_two(),
            );
            self.light_buffer = lb;
            self.visible_buffer = vb;
            self.g0 = Self::make_g0(
                &ctx.device,
                &self.g0_layout,
                &self.frame_buffer,
                &self.material_buffer,
                &self.instance_buffer,
                &self.light_buffer,
                &self.visible_buffer,
            );
        }
        let frame = GpuFrame {
            view: mat_array(view),
            proj: mat_array(proj),
            inv_proj: mat_array(proj.inverse()),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            background: self.background.extend(1.0).into(),
            near: camera.near,
            far: camera.far,
            light_count: lists.forward.len() as u32,
            _pad: 0,
        };
        ctx.queue
            .write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&frame));
        if !lists.gpu.is_empty() {
            ctx.queue
                .write_buffer(&self.light_buffer, 0, bytemuck::cast_slice(&lists.gpu));
        }
        if !visible.is_empty() {
            ctx.queue
                .write_buffer(&self.visible_buffer, 0, bytemuck::cast_slice(&visible));
        }

        // Transparent instances, far to near.
        let mut blend: Vec<(f32, &BlendItem)> = self
            .blend_items
            .iter()
            .map(|b| (view.transform_point3(b.center).z, b))
            .collect();
        blend.sort_by(|a, b| a.0.total_cmp(&b.0));

        let mut stats = RenderStats {
            technique,
            width,
            height,
            triangles: self.triangles,
            lights_total: self.lights.len(),
            lights_visible: lists.forward.len(),
            lights_fullscreen: lists.fullscreen.len(),
            volumes_outside: lists.sphere_out.len() + lists.cone_out.len(),
            volumes_inside: lists.sphere_in.len() + lists.cone_in.len(),
            gbuffer_bytes_per_pixel: match technique {
                Technique::Deferred => GBUFFER_BYTES_COMPRESSED,
                Technique::LightPrepass => GBUFFER_BYTES_COMPRESSED,
                Technique::Forward => 4,
            },
            ..Default::default()
        };
        let t = self.targets.as_ref().expect("targets were just created");
        let mut pass_names: Vec<String> = Vec::new();
        let mut draws = 0usize;
        let label = format!("deferred frame ({technique}, {width}x{height})");
        let encoded = ctx.scoped(&label, |device| {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(&label),
            });
            let clear_bg = clear_to(self.background.extend(1.0));
            let zero = clear_to(Vec4::ZERO);
            let load = wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            };
            let depth_clear = wgpu::RenderPassDepthStencilAttachment {
                view: &t.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            };
            // read-only: the passes sample the same texture
            let depth_read = wgpu::RenderPassDepthStencilAttachment {
                view: &t.depth_view,
                depth_ops: None,
                stencil_ops: None,
            };
            let light_pass = |encoder: &mut wgpu::CommandEncoder,
                              names: &mut Vec<String>,
                              specular_ops: wgpu::Operations<wgpu::Color>,
                              draws: &mut usize| {
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("deferred light pass"),
                    color_attachments: &[
                        attach(&t.diffuse_view, zero),
                        attach(&t.specular_view, specular_ops),
                    ],
                    depth_stencil_attachment: Some(depth_read.clone()),
                    timestamp_writes: timestamp(timer, names, "lights"),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_bind_group(0, &self.g0, &[]);
                rp.set_bind_group(1, &t.bg_light, &[]);
                if !fullscreen_range.is_empty() {
                    rp.set_pipeline(self.pipeline(Pipe::LightFullscreen));
                    rp.draw(0..3, fullscreen_range.clone());
                    *draws += 1;
                }
                rp.set_vertex_buffer(0, self.volume_vertices.slice(..));
                rp.set_index_buffer(self.volume_indices.slice(..), wgpu::IndexFormat::Uint32);
                for (pipe, spheres, cones) in [
                    (Pipe::VolumeFront, &sphere_out, &cone_out),
                    (Pipe::VolumeBack, &sphere_in, &cone_in),
                ] {
                    if spheres.is_empty() && cones.is_empty() {
                        continue;
                    }
                    rp.set_pipeline(self.pipeline(pipe));
                    if !spheres.is_empty() {
                        rp.draw_indexed(self.sphere_indices.clone(), 0, spheres.clone());
                        *draws += 1;
                    }
                    if !cones.is_empty() {
                        rp.draw_indexed(
                            self.cone_indices.clone(),
                            self.cone_base_vertex,
                            cones.clone(),
                        );
                        *draws += 1;
                    }
                }
            };

            match technique {
                Technique::Deferred => {
                    {
                        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("deferred geometry pass"),
                            color_attachments: &[
                                attach(&t.albedo_view, zero),
                                attach(&t.normal_view, zero),
                                attach(&t.specular_view, zero),
                            ],
                            depth_stencil_attachment: Some(depth_clear.clone()),
                            timestamp_writes: timestamp(timer, &mut pass_names, "geometry"),
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                        self.draw_batches(&mut rp, self.batches.iter(), Pipe::GBuffer, &mut draws);
                    }
                    light_pass(&mut encoder, &mut pass_names, load, &mut draws);
                    {
                        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("deferred composition"),
                            color_attachments: &[attach(&t.scene_view, zero)],
                            depth_stencil_attachment: None,
                            timestamp_writes: timestamp(timer, &mut pass_names, "composition"),
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                        rp.set_pipeline(self.pipeline(Pipe::Compose));
                        rp.set_bind_group(0, &self.g0, &[]);
                        rp.set_bind_group(1, &t.bg_all, &[]);
                        rp.draw(0..3, 0..1);
                        draws += 1;
                    }
                }
                Technique::LightPrepass => {
                    {
                        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("light pre-pass depth + normals"),
                            color_attachments: &[
                                attach(&t.albedo_view, zero),
                                attach(&t.normal_view, zero),
                            ],
                            depth_stencil_attachment: Some(depth_clear.clone()),
                            timestamp_writes: timestamp(timer, &mut pass_names, "depth+normals"),
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                        self.draw_batches(&mut rp, self.batches.iter(), Pipe::Prepass, &mut draws);
                    }
                    light_pass(&mut encoder, &mut pass_names, zero, &mut draws);
                    {
                        let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                            label: Some("light pre-pass final geometry"),
                            color_attachments: &[
                                attach(&t.scene_view, clear_bg),
                                attach(&t.albedo_view, load),
                            ],
                            depth_stencil_attachment: Some(depth_read.clone()),
                            timestamp_writes: timestamp(timer, &mut pass_names, "final geometry"),
                            occlusion_query_set: None,
                            multiview_mask: None,
                        });
                        rp.set_bind_group(1, &t.bg_final, &[]);
                        self.draw_batches(&mut rp, self.batches.iter(), Pipe::LppFinal, &mut draws);
                    }
                }
                Technique::Forward => {
                    let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("forward pass"),
                        color_attachments: &[
                            attach(&t.scene_view, clear_bg),
                            attach(&t.albedo_view, zero),
                            attach(&t.normal_view, zero),
                        ],
                        depth_stencil_attachment: Some(depth_clear.clone()),
                        timestamp_writes: timestamp(timer, &mut pass_names, "forward"),
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    self.draw_batches(&mut rp, self.batches.iter(), Pipe::Forward, &mut draws);
                }
            }
            if !blend.is_empty() {
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("deferred transparency (forward)"),
                    color_attachments: &[attach(&t.scene_view, load)],
                    depth_stencil_attachment: Some(depth_read.clone()),
                    timestamp_writes: timestamp(timer, &mut pass_names, "transparency"),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                self.draw_batches(
                    &mut rp,
                    blend.iter().map(|(_, b)| &b.batch),
                    Pipe::ForwardBlend,
                    &mut draws,
                );
            }
            for (pipe, range, name) in [
                (Pipe::AuxA, 0..3, "aux depth/normal/position"),
                (Pipe::AuxB, 3..6, "aux albedo/material/specular"),
            ] {
                let attachments: Vec<_> = t.aux[range]
                    .iter()
                    .map(|(_, _, v)| attach(v, zero))
                    .collect();
                let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(name),
                    color_attachments: &attachments,
                    depth_stencil_attachment: None,
                    timestamp_writes: timestamp(timer, &mut pass_names, name),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                rp.set_pipeline(self.pipeline(pipe));
                rp.set_bind_group(0, &self.g0, &[]);
                rp.set_bind_group(1, &t.bg_all, &[]);
                rp.draw(0..3, 0..1);
                draws += 1;
            }
            if let Some(timer) = timer {
                timer.resolve(&mut encoder, pass_names.len() as u32);
            }
            ctx.queue.submit([encoder.finish()]);
        });
        encoded?;
        stats.draw_calls = draws;
        stats.cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        if let Some(timer) = timer {
            let ms = timer.read_ms(ctx, pass_names.len() as u32)?;
            stats.gpu_ms = Some(ms.iter().sum());
            stats.pass_ms = pass_names.into_iter().zip(ms).collect();
        }
        let errors = ctx.take_uncaptured_errors();
        if let Some(first) = errors.first() {
            return Err(RenderError::Gpu(GpuError::Validation {
                what: label,
                message: first.clone(),
            }));
        }
        log::debug!(
            "{}: {technique} frame {width}x{height}: {} lights visible of {}, {} draws, cpu {:.2} ms",
            self.name,
            stats.lights_visible,
            stats.lights_total,
            stats.draw_calls,
            stats.cpu_ms
        );
        let output = RenderOutput {
            width,
            height,
            scene: t.scene.clone(),
            aux: t
                .aux
                .iter()
                .map(|(n, tex, _)| (n.clone(), tex.clone()))
                .collect(),
            camera: camera.camera_std(aspect),
            gbuffer: GBufferTextures {
                depth: t.depth.clone(),
                albedo: t.albedo.clone(),
                normal: t.normal.clone(),
                light_diffuse: t.diffuse.clone(),
                light_specular: t.specular.clone(),
            },
        };
        Ok((output, stats))
    }
    /// Draws `batches` with the pipeline `pipe(cull)` of each, switching pipelines and
    /// material bind groups only when they change.
    fn draw_batches<'a>(
        &self,
        rp: &mut wgpu::RenderPass<'_>,
        batches: impl Iterator<Item = &'a Batch>,
        pipe: impl Fn(Cull) -> Pipe,
        draws: &mut usize,
    ) {
        rp.set_bind_group(0, &self.g0, &[]);
        rp.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        rp.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        let mut current: Option<(Cull, usize)> = None;
        for b in batches {
            if current.map(|c| c.0) != Some(b.cull) {
                rp.set_pipeline(self.pipeline(pipe(b.cull)));
            }
            if current.map(|c| c.1) != Some(b.material) {
                rp.set_bind_group(2, &self.material_groups[b.material], &[]);
            }
            current = Some((b.cull, b.material));
            rp.draw_indexed(b.indices.clone(), b.base_vertex, b.instances.clone());
            *draws += 1;
        }
    }
}

fn attach(
    view: &wgpu::TextureView,
    ops: wgpu::Operations<wgpu::Color>,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops,
    })
}

fn clear_to(c: Vec4) -> wgpu::Operations<wgpu::Color> {
    wgpu::Operations {
        load: wgpu::LoadOp::Clear(wgpu::Color {
            r: f64::from(c.x),
            g: f64::from(c.y),
            b: f64::from(c.z),
            a: f64::from(c.w),
        }),
        store: wgpu::StoreOp::Store,
    }
}

/// Timestamp writes for the next pass, recording its name.
fn timestamp<'a>(
    timer: Option<&'a GpuTimer>,
    names: &mut Vec<String>,
    name: &str,
) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
    let i = names.len() as u32;
    names.push(name.to_string());
    timer.and_then(|t| t.pass_writes(i))
}

/// The six view-space frustum planes `(n, d)` with `n·p + d >= 0` inside, for a
/// projection with depth 0..1 (Gribb-Hartmann).
fn frustum_planes(proj: &Mat4) -> [Vec4; 6] {
    let r = |i: usize| proj.row(i);
    let planes = [
        r(3) + r(0),
        r(3) - r(0),
        r(3) + r(1),
        r(3) - r(1),
        r(2),
        r(3) - r(2),
    ];
    planes.map(|p| p / p.truncate().length().max(1e-20))
}

/// Bounding sphere of a cone with apex `apex`, unit axis `axis`, length `h` and base
/// radius `rb`.
fn cone_bounding_sphere(apex: Vec3, axis: Vec3, h: f32, rb: f32) -> (Vec3, f32) {
    if rb <= h {
        let c = (h * h + rb * rb) / (2.0 * h);
        (apex + axis * c, c)
    } else {
        (apex + axis * h, rb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn struct_sizes_match_wgsl() {
        assert_eq!(std::mem::size_of::<GpuFrame>(), 240);
        assert_eq!(std::mem::size_of::<GpuMaterial>(), 64);
        assert_eq!(std::mem::size_of::<GpuInstance>(), 144);
        assert_eq!(std::mem::size_of::<GpuLight>(), 80);
        assert_eq!(std::mem::size_of::<Vertex>(), 48);
    }

    #[test]
    fn frustum_planes_contain_the_view_axis() {
        let proj = super::super::scene::perspective_rh(1.0, 1.5, 0.1, 100.0);
        let planes = frustum_planes(&proj);
        let inside = Vec3::new(0.0, 0.0, -10.0);
        assert!(planes.iter().all(|p| p.truncate().dot(inside) + p.w > 0.0));
        let behind = Vec3::new(0.0, 0.0, 10.0);
        assert!(planes.iter().any(|p| p.truncate().dot(behind) + p.w < 0.0));
    }

    #[test]
    fn cone_sphere_contains_the_cone() {
        let (c, r) = cone_bounding_sphere(Vec3::ZERO, Vec3::Z, 2.0, 1.0);
        for p in [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, -1.0, 2.0),
        ] {
            assert!((p - c).length() <= r + 1e-5);
        }
    }

    #[test]
    fn technique_names_parse() {
        for t in Technique::ALL {
            assert_eq!(t.name().parse::<Technique>().unwrap(), t);
        }
        assert!("tiled".parse::<Technique>().is_err());
    }
}
