//! [`RendererOptions`]: what is fixed when a renderer is made (normal
//! encoding, mipmaps, variants, light culling, shadows, the compute light
//! pass, the G-buffer layout). Its own home, so the parts that read it need not import the renderer.

use super::clusters::LightCulling;
use super::gbuffer_layout::GbufferLayout;
use super::material::VariantMode;
use super::normal::NormalEncoding;
use super::shadows::{ShadowMode, DEFAULT_SHADOW_LAYERS, DEFAULT_SHADOW_SIZE};

/// Options fixed when a [`Renderer`] is created.
#[derive(Debug, Clone)]
pub struct RendererOptions {
    /// How normals are stored in the G-buffer.
    pub normal_encoding: NormalEncoding,
    /// Generate mipmaps for scene textures (box filter).
    pub mipmaps: bool,
    /// How material features select shader code.
    pub variants: VariantMode,
    /// How the light passes pick the lights of a pixel.
    pub light_culling: LightCulling,
    /// Shadow maps for the scene's lights, and their filter (`shadows.rs`).
    pub shadows: ShadowMode,
    /// Side of each shadow map in texels ([`super::shadows::MIN_SHADOW_SIZE`]..=[`super::shadows::MAX_SHADOW_SIZE`]
    /// and the device's limit).
    pub shadow_size: u32,
    /// Shadow-map layers per frame (a directional light takes 4, a point light
    /// 6, a spot light 1); lights past it are unshadowed, with a warning.
    pub shadow_budget: u32,
    /// Keep shadow-map layers between frames and render a layer again only
    /// when its light or a caster in its volume changed (default;
    /// `shadow_cache.rs` has the rule). Off: every layer every frame.
    pub shadow_cache: bool,
    /// Place directional cascades on a world-fixed set of squares, so that a
    /// moving camera keeps them (default; `cascades.rs` has the rule). Off:
    /// each cascade fitted to its slice afresh every frame (the reference).
    pub stable_cascades: bool,
    /// The clustered light pass of deferred shading and the light pre-pass as a
    /// compute dispatch (default; `light_compute.rs`), or as the full-screen
    /// fragment pass it replaces (the reference it is tested against).
    pub compute_lighting: bool,
    /// How deferred shading fills the G-buffer: one raster pass running the
    /// surface shaders (default), or a visibility buffer resolved in compute
    /// (`visibility.rs`).
    pub gbuffer_layout: GbufferLayout,
}

impl Default for RendererOptions {
    fn default() -> Self {
        RendererOptions {
            normal_encoding: NormalEncoding::default(),
            mipmaps: true,
            variants: VariantMode::default(),
            light_culling: LightCulling::default(),
            shadows: ShadowMode::default(),
            shadow_size: DEFAULT_SHADOW_SIZE,
            shadow_budget: DEFAULT_SHADOW_LAYERS,
            shadow_cache: true,
            stable_cascades: true,
            compute_lighting: true,
            gbuffer_layout: GbufferLayout::default(),
        }
    }
}
