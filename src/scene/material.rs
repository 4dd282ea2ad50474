//! The material model: a [`Material`] is a surface shader and a lighting shader,
//! each a [`ShaderBinding`] with its parameter values and textures, plus the alpha
//! mode and sidedness. The shaders are checked in `shader/material/` and resolved
//! for the renderer in `render/material/`.

use glam::{Vec3, Vec4};

/// How a material's alpha is used (glTF `alphaMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AlphaMode {
    /// Alpha ignored.
    #[default]
    Opaque,
    /// Fragments with alpha below the cut-off are discarded; drawn deferred.
    Mask,
    /// Blended; drawn forward after composition, sorted back to front.
    Blend,
}

/// A material (the materials-and-effects paper, section 2): a *surface shader* that computes the
/// surface's colours, normal, roughness, emission and coverage, and a *lighting
/// shader* that turns one light into reflected diffuse and specular light. Both are
/// WGSL files (`shaders/materials/*.wgsl` or the user's) with the parameter values
/// and textures given here; the renderer generates every full shader from them
/// (see `docs/materials.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub surface: ShaderBinding,
    pub lighting: ShaderBinding,
    pub alpha_mode: AlphaMode,
    /// Coverage below which MASK fragments are discarded.
    pub alpha_cutoff: f32,
    /// Both faces are drawn; back faces see the flipped normal.
    pub double_sided: bool,
}

/// A material shader with its settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ShaderBinding {
    /// The shader's name: `standard`, `triplanar`, `lambert`, `phong`,
    /// `blinn_phong`, `cook_torrance`, or a user's `NAME` (`NAME.wgsl`).
    pub shader: String,
    /// The folder a user's shader is looked up in first (the material file's).
    pub dir: Option<std::path::PathBuf>,
    /// Parameter values by uniform field name (numbers; vectors as several).
    pub params: Vec<(String, Vec<f64>)>,
    /// Textures by the shader's texture variable name: indices into
    /// [`Scene::textures`](super::Scene::textures).
    pub textures: Vec<(String, usize)>,
}

impl ShaderBinding {
    /// A shader with no settings (its defaults).
    pub fn new(shader: &str) -> ShaderBinding {
        ShaderBinding {
            shader: shader.to_string(),
            ..Default::default()
        }
    }

    /// Sets parameter `name` (replacing an earlier value).
    pub fn set(&mut self, name: &str, value: &[f64]) -> &mut Self {
        self.params.retain(|(n, _)| n != name);
        self.params.push((name.to_string(), value.to_vec()));
        self
    }

    /// Builder form of [`ShaderBinding::set`].
    pub fn with(mut self, name: &str, value: &[f64]) -> Self {
        self.set(name, value);
        self
    }

    /// Binds texture variable `name` to scene texture `index`.
    pub fn set_texture(&mut self, name: &str, index: usize) -> &mut Self {
        self.textures.retain(|(n, _)| n != name);
        self.textures.push((name.to_string(), index));
        self
    }

    /// The value set for `name`, if any.
    pub fn param(&self, name: &str) -> Option<&[f64]> {
        self.params
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The scene texture bound to `name`, if any.
    pub fn texture(&self, name: &str) -> Option<usize> {
        self.textures
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, t)| *t)
    }
}

impl Material {
    /// A material of `surface` and `lighting` shaders, opaque and one-sided.
    pub fn new(name: &str, surface: ShaderBinding, lighting: ShaderBinding) -> Material {
        Material {
            name: name.to_string(),
            surface,
            lighting,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
        }
    }

    /// The standard surface with a diffuse colour and a grey specular reflectance
    /// `specular` (F0), lit by the paper's Phong model with exponent `shininess`
    /// (`SPECULAR_POWER`).
    pub fn phong(name: &str, diffuse: Vec3, specular: f32, shininess: f32) -> Material {
        let s = f64::from(specular.clamp(0.0, 1.0));
        let c = diffuse.to_array().map(f64::from);
        Material::new(
            name,
            ShaderBinding::new("standard")
                .with("base_color", &[c[0], c[1], c[2], 1.0])
                .with("specular", &[s, s, s])
                .with("metallic", &[0.0])
                .with(
                    "roughness",
                    &[f64::from(roughness_from_shininess(shininess))],
                ),
            ShaderBinding::new("phong")
                .with("specular_power", &[f64::from(shininess.clamp(1.0, 4096.0))]),
        )
    }

    /// glTF 2.0 metallic-roughness: the standard surface with these factors, lit by
    /// Cook-Torrance (GGX, height-correlated Smith, Schlick) as in the glTF
    /// specification's Appendix B.
    pub fn metallic_roughness(
        name: &str,
        base_color: Vec4,
        metallic: f32,
        roughness: f32,
    ) -> Material {
        Material::new(
            name,
            ShaderBinding::new("standard")
                .with("base_color", &base_color.to_array().map(f64::from))
                .with("metallic", &[f64::from(metallic.clamp(0.0, 1.0))])
                .with("roughness", &[f64::from(roughness.clamp(0.0, 1.0))]),
            ShaderBinding::new("cook_torrance"),
        )
    }

    /// The surface's `name` parameter as up to four floats (`default` where unset).
    pub fn surface_param(&self, name: &str, default: [f32; 4]) -> [f32; 4] {
        let mut out = default;
        if let Some(v) = self.surface.param(name) {
            for (o, x) in out.iter_mut().zip(v) {
                *o = *x as f32;
            }
        }
        out
    }
}

/// Perceptual roughness with the highlight width of a Phong exponent: the usual
/// Beckmann-to-Phong mapping `α = 2 / r⁴ − 2` inverted (α_beckmann = r²).
pub fn roughness_from_shininess(shininess: f32) -> f32 {
    (2.0 / (shininess.max(1.0) + 2.0))
        .powf(0.25)
        .clamp(0.0, 1.0)
}
