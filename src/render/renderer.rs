//! The GPU renderer: deferred shading with a compressed G-buffer and light volumes,
//! light pre-pass, and forward shading, all producing the same outputs from the
//! same materials (surface + lighting shaders, see [`super::material`]).
//!
//! # Frame (deferred)
//!
//! 1. Geometry pass: opaque and MASK objects run their surface shader and fill the
//!    G-buffer ([`super::targets`]); emission and ambient × occlusion start the
//!    specular light buffer. With [`super::GbufferLayout::Visibility`] a raster
//!    pass writes depth and triangle ids instead, and compute dispatches
//!    resolve the materials into the same targets (`super::visibility`).
//! 2. Light pass into two `Rgba16Float` light buffers: every light's lighting
//!    shader (chosen per pixel by the lighting-model id in the G-buffer). By
//!    default ([`LightCulling::Clustered`], [`super::clusters`]) one compute
//!    pass (`light_compute.rs`; a full-screen fragment pass with
//!    [`RendererOptions::compute_lighting`] off) in which each pixel shades the
//!    directional lights and the point and
//!    spot lights listed for its cluster (32-pixel tiles × 24 depth slices over
//!    the geometry's depth range, binned on the GPU). [`LightCulling::Volumes`]
//!    keeps Tang et al.'s light volumes: directional lights as full-screen
//!    triangles, point lights as icosphere volumes and spot lights as cone
//!    volumes, culled against the view frustum on the CPU, all lights of a kind
//!    in one instanced additive draw; volumes that hold the camera (or the near
//!    plane) are drawn as back faces with depth test `GREATER_EQUAL`, the others
//!    as front faces with `LESS`, and one that holds the camera and crosses the
//!    far plane full-screen. [`LightCulling::None`] shades every light at every
//!    pixel (the reference).
//! 3. Composition: `diffuse colour × diffuse light + specular light`, through the
//!    fog when there is one ([`super::fog`]), into the HDR scene texture
//!    (`Rgba16Float`, linear radiance); the background where nothing was drawn.
//!    The compute light pass composes in its own dispatch.
//! 4. Transparency: BLEND objects forward, sorted back to front, depth-tested (not
//!    written) against the opaque depth, lit by every visible light.
//! 5. Resolve: the G-buffer decoded into the `AUX.*` images.
//!
//! [`Technique::LightPrepass`] (the deferred-rendering survey) replaces 1–3 with a depth + normal +
//! specular pass, the same light pass, and a second geometry pass that runs the
//! surface shader again and reads the light buffers; [`Technique::Forward`] runs
//! the surface shader and the lighting shader of the lights of the fragment's
//! cluster (every visible light with [`LightCulling::Volumes`]) per fragment.

use super::cluster_gpu::GpuClusters;
pub use super::error::RenderError;
use super::gpu_types::*;
use super::light_buffers::LightBuffers;
use super::light_compute::{ComputeLighting, LightCompute};
use super::light_view_gpu::LightView;
use super::lights::LightVolumes;
use super::material::MaterialSet;
use super::motion::MotionPass;
pub use super::options::RendererOptions;
use super::pipelines::{Layouts, Pipelines};
use super::shadow_pass::ShadowMaps;
pub use super::shadows::{
    ShadowMode, DEFAULT_SHADOW_LAYERS, DEFAULT_SHADOW_SIZE, MAX_SHADOW_SIZE, MIN_SHADOW_SIZE,
};
use super::targets::{TargetLayouts, Targets};
use super::upload::{Geometry, MaterialResources};
use super::visibility::{VisInputs, VisibilityBuffer};
use super::world_lights::WorldLights;
use crate::gpu::context::{GpuContext, GpuError, GpuTimer};
use crate::scene::{Camera, Light, Scene};
use glam::{Mat4, Vec3};
use std::time::Instant;
use wgpu::util::DeviceExt;

pub use super::clusters::LightCulling;
pub use super::frame_motion::{jittered, FrameMotion};
pub use super::output::{GBufferTextures, RenderOutput, RenderStats};
pub use super::targets::{GBUFFER_BYTES_COMPRESSED, GBUFFER_BYTES_TRADITIONAL};
pub use super::technique::Technique;

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

/// GPU resources of one scene; renders frames of any size, camera and technique.
pub struct Renderer {
    pub(super) opts: RendererOptions,
    /// The auxiliary images and formats: [`super::published_aux`] (depth is
    /// R16Float where R32Float cannot be rendered: GL on llvmpipe).
    pub(super) aux_formats: Vec<(String, crate::script::types::Format)>,
    pub(super) name: String,
    pub(super) lights: Vec<Light>,
    pub(crate) background: Vec3,
    /// The fog of the template (none by default).
    pub(super) fog: Option<super::fog::Fog>,
    /// The background of the last frame (fogged).
    pub(crate) frame_background: Vec3,
    /// World-space bounds of the geometry: the cluster slices span its depth.
    pub(super) bounds: crate::scene::Aabb,
    pub(crate) shadow_maps: ShadowMaps,
    pub(super) triangles: usize,
    pub(crate) materials: MaterialSet,
    pub(crate) geometry: Geometry,
    pub(crate) material_gpu: MaterialResources,
    pub(crate) volumes: LightVolumes,
    pub(super) frame_buffer: wgpu::Buffer,
    material_info_buffer: wgpu::Buffer,
    pub(super) light_buffers: LightBuffers,
    /// The clustered light lists, built on the GPU each frame.
    pub(super) clusters: GpuClusters,
    /// The lights in view space, culled and given their cluster records on
    /// the GPU each frame (clustered and unculled lighting).
    pub(super) light_view: LightView,
    /// The lights in world space, as `light_view` holds them (`None`: to be
    /// built and uploaded, after a change of the lights).
    pub(super) world_lights: Option<WorldLights>,
    /// The light uploads and the grid the cluster reservation was read back
    /// for.
    pub(super) cluster_sizing: Option<(u64, u32, u32)>,
    /// The compute light passes.
    pub(super) light_compute: ComputeLighting,
    pub(crate) layouts: Layouts,
    pub(crate) g0: wgpu::BindGroup,
    pub(crate) pipelines: Pipelines,
    dummy_light: wgpu::TextureView,
    pub(crate) targets: Option<Targets>,
    /// Image-based lighting and the background (`super::environment`).
    pub(crate) environment: super::environment::EnvironmentLighting,
    /// (technique, forward light count) whose pipelines all exist.
    pub(super) ensured: std::collections::HashSet<(Technique, u32)>,
    /// The motion-vector passes (`AUX.motion`).
    pub(crate) motion: MotionPass,
    /// The visibility buffer of deferred shading, where the options ask for
    /// one and the adapter can have it (`super::visibility`).
    pub(crate) visibility: Option<VisibilityBuffer>,
    /// The instances' rest transforms (scene order), and whether the instance
    /// buffer holds other ones (a posed frame was rendered).
    pub(super) rest_transforms: Vec<Mat4>,
    pub(super) posed: bool,
}

/// A 1x1 texture view with one texel.
fn one_texel(
    ctx: &GpuContext,
    label: &str,
    format: wgpu::TextureFormat,
    texel: &[u8],
) -> Result<wgpu::TextureView, GpuError> {
    Ok(ctx
        .upload_texture(label, 1, 1, format, texel, wgpu::TextureUsages::empty())?
        .create_view(&wgpu::TextureViewDescriptor {
            label: Some(&format!("{label} view")),
            ..Default::default()
        }))
}

/// The 1x1 stand-ins: white for a material without a texture, and a zero
/// `Rgba16Float` for the light buffers while they are render targets.
fn stand_in_textures(ctx: &GpuContext) -> Result<(wgpu::TextureView, wgpu::TextureView), GpuError> {
    let white = one_texel(
        ctx,
        "deferred default white texture",
        wgpu::TextureFormat::Rgba8Unorm,
        &[255, 255, 255, 255],
    )?;
    let dummy_light = one_texel(
        ctx,
        "deferred dummy rgba16f",
        wgpu::TextureFormat::Rgba16Float,
        &[0; 8],
    )?;
    Ok((white, dummy_light))
}

/// The renderer's shaders read the depth buffer with textureLoad, which naga
/// cannot translate to GLSL: the GL backend is refused.
fn check_backend(ctx: &GpuContext) -> Result<(), RenderError> {
    if ctx.info.backend == wgpu::Backend::Gl {
        return Err(RenderError::Gpu(GpuError::UnsupportedFormat {
            what: "the deferred renderer".into(),
            format: "Depth32Float read in shaders".into(),
            adapter: ctx.info.name.clone(),
            reason: "the GL backend cannot read depth textures in shaders; use Vulkan (software: apt-get install mesa-vulkan-drivers)".into(),
        }));
    }
    Ok(())
}

/// The material-info buffer (lighting model and alpha cutoff of each
/// material), the frame-uniform buffer and the bind-group layouts.
fn create_frame_buffers(
    ctx: &GpuContext,
    materials: &MaterialSet,
) -> Result<(wgpu::Buffer, wgpu::Buffer, Layouts), GpuError> {
    let mut infos: Vec<GpuMaterialInfo> = materials
        .materials
        .iter()
        .map(|m| GpuMaterialInfo {
            model: m.lighting as u32,
            alpha_cutoff: m.alpha_cutoff,
            _pad: [0; 2],
        })
        .collect();
    if infos.is_empty() {
        infos.push(bytemuck::Zeroable::zeroed());
    }
    let aux_compute = (
        super::pipelines::aux_compute_supported(ctx),
        super::pipelines::aux_b_compute_supported(ctx),
    );
    ctx.scoped("deferred renderer: scene upload", |device| {
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let material_info_buffer = init(
            "deferred material info",
            bytemuck::cast_slice(&infos),
            wgpu::BufferUsages::STORAGE,
        );
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("deferred frame uniforms"),
            size: std::mem::size_of::<GpuFrame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (
            material_info_buffer,
            frame_buffer,
            Layouts::new(device, aux_compute),
        )
    })
}

/// Image-based lighting for the scene's background, with its environment map
/// when it has one.
fn load_environment(
    ctx: &GpuContext,
    scene: &Scene,
) -> Result<super::environment::EnvironmentLighting, RenderError> {
    let mut environment = super::environment::EnvironmentLighting::new(ctx, scene.background)?;
    if let Some(env) = &scene.environment {
        let map = env.load()?;
        environment.set(ctx, Some((env, &map)))?;
    }
    Ok(environment)
}

/// The AUX images and their formats; AUX.depth is R16Float (with a warning)
/// where the adapter cannot render R32Float.
fn aux_formats(ctx: &GpuContext) -> Vec<(String, crate::script::types::Format)> {
    let depth_renderable = ctx.format_support(wgpu::TextureFormat::R32Float).render;
    if !depth_renderable {
        log::warn!(
            "this adapter cannot render to R32Float: AUX.depth is R16Float (half precision)"
        );
    }
    super::output::published_aux(depth_renderable)
}

/// The info line of a renderer made: the time it took and what it uploaded.
fn log_ready(
    name: &str,
    start: Instant,
    (geometry, triangles): (&Geometry, usize),
    materials: &MaterialSet,
    material_gpu: &MaterialResources,
) {
    log::info!(
        "{name}: renderer ready in {:.1} ms: {} vertices, {} triangles, {} opaque batches, {} transparent instances, {} materials ({} surface, {} lighting shaders), {} textures",
        start.elapsed().as_secs_f64() * 1e3,
        geometry.vertices,
        triangles,
        geometry.batches.len(),
        geometry.blend_items.len(),
        materials.materials.len(),
        materials.surfaces.len(),
        materials.lightings.len(),
        material_gpu.textures
    );
}

/// Lights of zero, negative or non-finite intensity are ignored, not an error
/// (glTF files and generators produce them, e.g. a light animated to off): one
/// warning names how many.
fn warn_dark_lights(scene: &str, lights: &[Light]) {
    let dark: Vec<&str> = lights
        .iter()
        .filter(|l| {
            let c = l.color * l.intensity;
            !(c.is_finite() && c.max_element() > 0.0)
        })
        .map(|l| l.name.as_str())
        .collect();
    if let Some(first) = dark.first() {
        log::warn!(
            "{scene}: {} light(s) with zero, negative or non-finite intensity ignored (first: `{first}`)",
            dark.len()
        );
    }
}

impl Renderer {
    /// Resolves the scene's materials, uploads the scene (geometry, materials,
    /// textures); shaders are generated and compiled on first use.
    pub fn new(
        ctx: &GpuContext,
        scene: &Scene,
        opts: &RendererOptions,
    ) -> Result<Renderer, RenderError> {
        let start = Instant::now();
        check_backend(ctx)?;
        scene.validate()?;
        let materials = MaterialSet::build(scene).map_err(|e| RenderError::Material(e.0))?;
        let device = &ctx.device;
        let name = scene.name.clone();
        let geometry = Geometry::upload(ctx, scene, &materials)?;
        let (white, dummy_light) = stand_in_textures(ctx)?;
        let material_gpu =
            MaterialResources::upload(ctx, scene, &materials, &geometry, opts.mipmaps, &white)?;
        let (material_info_buffer, frame_buffer, layouts) = create_frame_buffers(ctx, &materials)?;
        let volumes = LightVolumes::new(ctx)?;
        let light_buffers = LightBuffers::new(device);
        let shadow_maps = ShadowMaps::new(ctx, opts, &geometry)?;
        let light_view = LightView::new(ctx)?;
        let clusters = GpuClusters::new(ctx, &light_view)?;
        let environment = load_environment(ctx, scene)?;
        let g0 = light_buffers.group0(
            device,
            &layouts.g0,
            &frame_buffer,
            &material_info_buffer,
            &geometry.instance_buffer,
            match opts.light_culling {
                LightCulling::Volumes => &light_buffers.lights,
                _ => light_view.lights(),
            },
            &clusters,
            &shadow_maps,
            &environment,
        );
        let triangles = scene.triangle_count();
        log_ready(
            &name,
            start,
            (&geometry, triangles),
            &materials,
            &material_gpu,
        );
        let aux_formats = aux_formats(ctx);
        warn_dark_lights(&name, &scene.lights);
        let motion = MotionPass::new(ctx)?;
        let visibility = match opts.gbuffer_layout {
            super::GbufferLayout::Fat => None,
            super::GbufferLayout::Visibility => VisibilityBuffer::new(
                ctx,
                &VisInputs {
                    materials: &materials,
                    geometry: &geometry,
                    material_gpu: &material_gpu,
                    layouts: &layouts,
                    normal_encoding: opts.normal_encoding.shader_id(),
                },
            )
            .map_err(RenderError::Material)?,
        };
        Ok(Renderer {
            visibility,
            aux_formats,
            opts: opts.clone(),
            name,
            lights: scene.lights.clone(),
            background: scene.background,
            fog: None,
            frame_background: scene.background,
            bounds: scene.bounds(),
            shadow_maps,
            triangles,
            pipelines: Pipelines::new(opts.variants, opts.normal_encoding.shader_id()),
            materials,
            geometry,
            material_gpu,
            volumes,
            frame_buffer,
            material_info_buffer,
            light_buffers,
            clusters,
            light_view,
            world_lights: None,
            cluster_sizing: None,
            light_compute: ComputeLighting::default(),
            layouts,
            g0,
            dummy_light,
            targets: None,
            environment,
            ensured: Default::default(),
            motion,
            rest_transforms: scene.instances.iter().map(|i| i.transform).collect(),
            posed: false,
        })
    }

    /// The vertices of the deformed (skinned, morphed) instances after the last
    /// frame rendered, read back from the GPU (a blocking read; for tests and
    /// inspection). Empty when the scene has none.
    pub fn deformed_vertices(
        &self,
        ctx: &GpuContext,
        scene: &Scene,
    ) -> Result<Vec<super::DeformedVertices>, RenderError> {
        super::upload::skinning::read_deformed(ctx, &self.geometry, scene)
    }

    /// The lights rendered (the scene's, or those given to [`Renderer::set_lights`]).
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// Replaces the lights without uploading the scene again.
    pub fn set_lights(&mut self, lights: Vec<Light>) {
        warn_dark_lights(&self.name, &lights);
        self.lights = lights;
        self.world_lights = None;
    }

    /// Fog applied by the lighting template (`None`: no fog).
    pub fn set_fog(&mut self, fog: Option<super::fog::Fog>) {
        self.fog = fog;
    }

    /// Linear colour of pixels without geometry.
    pub fn background_color(&self) -> Vec3 {
        self.background
    }

    /// Group 0 again, after a buffer or texture it binds was replaced.
    pub(crate) fn rebuild_group0(&mut self, ctx: &GpuContext) {
        self.g0 = self.light_buffers.group0(
            &ctx.device,
            &self.layouts.g0,
            &self.frame_buffer,
            &self.material_info_buffer,
            &self.geometry.instance_buffer,
            match self.opts.light_culling {
                LightCulling::Volumes => &self.light_buffers.lights,
                _ => self.light_view.lights(),
            },
            &self.clusters,
            &self.shadow_maps,
            &self.environment,
        );
    }

    /// The options the renderer was created with.
    pub fn options(&self) -> &RendererOptions {
        &self.opts
    }

    /// The scene's materials: shaders, variant features, lighting-model ids.
    pub fn materials(&self) -> &MaterialSet {
        &self.materials
    }

    /// Pipelines compiled so far.
    pub fn pipelines_created(&self) -> usize {
        self.pipelines.pipelines_created
    }

    /// Shader modules compiled so far.
    pub fn modules_created(&self) -> usize {
        self.pipelines.modules_created
    }

    /// The auxiliary images this renderer produces, with their formats (plan effects
    /// with these).
    pub fn aux_formats(&self) -> &[(String, crate::script::types::Format)] {
        &self.aux_formats
    }

    /// Whether AUX.depth, normal, position and motion are resolved by a
    /// compute dispatch (compute lighting on, and the adapter can store to
    /// their formats) rather than drawn.
    pub fn resolves_aux_in_compute(&self) -> bool {
        LightCompute::AuxResolve.aux_in_compute(self.opts.compute_lighting, &self.layouts)
    }

    /// Whether AUX.albedo, material and specular are resolved by a compute
    /// dispatch (compute lighting on, and the adapter can store to their
    /// formats) rather than drawn.
    pub fn resolves_aux_albedo_in_compute(&self) -> bool {
        LightCompute::AuxResolveB.aux_in_compute(self.opts.compute_lighting, &self.layouts)
    }

    /// With the visibility buffer ([`super::GbufferLayout::Visibility`], on
    /// an adapter that can have it): the opaque batches drawn into the
    /// G-buffer rather than resolved in compute. `None`: the fat G-buffer.
    pub fn visibility_fallback_batches(&self) -> Option<usize> {
        self.visibility.as_ref().map(|v| v.fallback_batches())
    }

    /// Creates the frame targets for `width`×`height` if the size changed.
    pub(super) fn ensure_targets(
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
        let aux: Vec<(String, wgpu::TextureFormat)> = self
            .aux_formats
            .iter()
            .map(|(n, f)| (n.clone(), crate::gpu::executor::wgpu_format(*f)))
            .collect();
        let targets = Targets::new(
            ctx,
            width,
            height,
            &aux,
            &TargetLayouts {
                gbuffer: &self.layouts.g1_gbuffer,
                light_buffers: &self.layouts.g1_light_buffers,
                dummy_light: &self.dummy_light,
                light_compute: &self.layouts.g2_light_compute,
                aux_compute: self.layouts.g2_aux_compute.as_ref(),
                aux_b_compute: self.layouts.g2_aux_b_compute.as_ref(),
                gbuffer_resolved: self.visibility.is_some(),
            },
        )?;
        if let Some(v) = &mut self.visibility {
            v.ensure_targets(ctx, &targets, &self.geometry);
        }
        self.targets = Some(targets);
        Ok(())
    }

    /// Renders one still frame (no motion, no jitter): [`Renderer::render_frame`]
    /// with [`FrameMotion::default`].
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        width: u32,
        height: u32,
        technique: Technique,
        timer: Option<&GpuTimer>,
    ) -> Result<(RenderOutput, RenderStats), RenderError> {
        self.render_frame(
            ctx,
            camera,
            &FrameMotion::default(),
            width,
            height,
            technique,
            timer,
        )
    }
}
