//! What a frame produces: the HDR scene, the AUX images, the G-buffer textures
//! and the frame's statistics.

use super::technique::Technique;
use crate::gpu::executor::CameraStd;
use crate::script::types::Format;
use std::collections::HashMap;

/// The G-buffer and light buffers of the last frame (for inspection and
/// [`super::gbuffer_images`]).
#[derive(Debug, Clone)]
pub struct GBufferTextures {
    /// `Depth32Float` (0 near .. 1 far; 1 = no geometry).
    pub depth: wgpu::Texture,
    /// `Rgba8UnormSrgb`: diffuse colour, a = material id / 255.
    pub albedo: wgpu::Texture,
    /// `Rgb10a2Unorm`: encoded normal (rg), roughness (b).
    pub normal: wgpu::Texture,
    /// `Rgba8UnormSrgb`: specular colour F0, a = lighting model id / 255.
    pub specular: wgpu::Texture,
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
    /// The `AUX.*` images, named and formatted as [`published_aux`]: `depth` R32Float linear view depth
    /// (`far` where nothing was drawn), `normal` Rgba16Float view-space normal (w = 1
    /// on geometry, 0 elsewhere), `position` Rgba16Float view-space position (w as
    /// for normal), `albedo` Rgba8UnormSrgb (a = coverage), `material` Rgba8Unorm
    /// (r = material id / 255, g = lighting model id / 255, b = roughness, a = 1),
    /// `specular` R16Float mean F0, `motion` Rg16Float motion vectors in pixels
    /// (current − previous position, x right, y down). Usage: TEXTURE_BINDING | COPY_SRC |
    /// RENDER_ATTACHMENT, and where the AUX resolve is a compute dispatch
    /// STORAGE_BINDING (albedo, which cannot be one, COPY_DST: its raw twin is
    /// copied in).
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
    /// Lights left after frustum culling (forward shades all of these per
    /// fragment). With cluster lists the GPU culls and counts them: timed
    /// frames read the count back; untimed frames report the global lights
    /// only ([`super::Renderer::read_visible_lights`] reads the count).
    pub lights_visible: usize,
    /// Full-screen light passes (ambient, directional, volumes that hold the camera
    /// and cross the far plane).
    pub lights_fullscreen: usize,
    /// Volumes drawn as front faces (camera outside).
    pub volumes_outside: usize,
    /// Volumes drawn as back faces (camera inside).
    pub volumes_inside: usize,
    /// Lights ignored because their intensity is zero, negative or not finite.
    pub lights_dark: usize,
    /// How the light passes picked each pixel's lights.
    pub light_culling: super::clusters::LightCulling,
    /// Light × cluster entries of the clustered lists, counted on the GPU: read
    /// back for timed frames only (reading waits for the GPU); 0 otherwise and
    /// without cluster lists.
    pub cluster_entries: usize,
    /// The longest cluster list (timed frames, as `cluster_entries`).
    pub cluster_max: usize,
    /// Bytes reserved on the GPU for the frame's cluster lists: the ranges and
    /// the conservative bound of the entries (each light's tile rectangle ×
    /// slices).
    pub cluster_bytes: u64,
    /// Pipelines and shader modules compiled so far by this renderer.
    pub pipelines: usize,
    pub shader_modules: usize,
    /// GPU milliseconds per pass (timestamp queries), when a timer was given.
    pub pass_ms: Vec<(String, f64)>,
    /// Sum of `pass_ms`.
    pub gpu_ms: Option<f64>,
    /// CPU milliseconds to prepare, encode and submit the frame, without
    /// `pipeline_ms`.
    pub cpu_ms: f64,
    /// Where `cpu_ms` went, in order: `pose` (transforms, joints, morph
    /// weights), `lights` (culling, shadow planning, the lights' footprints on
    /// the cluster grid), `upload` (light, cluster and frame data written to the
    /// queue), `record` (the passes recorded and submitted).
    pub cpu_split: Vec<(String, f64)>,
    /// CPU milliseconds creating the pipelines this frame used first: once per
    /// renderer and technique (and whenever the scene's material variants or
    /// light budget change), not a cost of every frame.
    pub pipeline_ms: f64,
    /// G-buffer bytes per pixel written by the technique's geometry pass(es):
    /// deferred 16 (diffuse+material id, normal+roughness, specular+model id,
    /// depth), light pre-pass 13 (normal+roughness, specular+model id, material
    /// id, depth), forward 16 (it shades with depth alone, 4, and fills the
    /// three colour targets for the AUX images).
    pub gbuffer_bytes_per_pixel: u32,
    /// Shadow-map layers this frame uses (`RendererOptions::shadow_budget`
    /// bounds them).
    pub shadow_layers: usize,
    /// Of those, the layers this frame rendered (the others kept their depths
    /// from an earlier frame: nothing in their light's view changed).
    pub shadow_layers_rendered: usize,
    /// Bytes of the shadow-map array texture (it grows to the most layers a
    /// frame has needed).
    pub shadow_map_bytes: u64,
}

/// The AUX images the renderer publishes to effects (`AUX.NAME`), with their
/// formats; each has the frame's size. The graph compiler plans with this list
/// (`InputDesc::with_aux`), so `fxrun --plan --scene` and a run agree.
/// `depth_renderable`: whether the adapter can render R32Float (GL on llvmpipe
/// cannot; AUX.depth is then R16Float).
pub fn published_aux(depth_renderable: bool) -> Vec<(String, Format)> {
    [
        // linear view depth (`far` where nothing was drawn)
        (
            "depth",
            if depth_renderable {
                Format::R32f
            } else {
                Format::R16f
            },
        ),
        // view-space normal, w = 1 on geometry
        ("normal", Format::Rgba16f),
        // view-space position, w = 1 on geometry
        ("position", Format::Rgba16f),
        // diffuse colour, a = coverage
        ("albedo", Format::Rgba8Srgb),
        // r = material id / 255, g = lighting model id / 255, b = roughness
        ("material", Format::Rgba8),
        // mean specular reflectance F0
        ("specular", Format::R16f),
        // motion vectors in pixels, current minus previous position, x right,
        // y down (`motion.rs`); always the last
        ("motion", Format::Rg16f),
    ]
    .into_iter()
    .map(|(n, f)| (n.to_string(), f))
    .collect()
}
