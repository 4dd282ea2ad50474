//! Render pipelines of the renderer, created on first use and cached by key:
//! geometry pipelines per (pass, material variant, culling, forward light count),
//! light-pass pipelines once per scene. Shader modules are cached separately, so
//! the count of each is what the variant mode costs.

use super::gpu_types::Vertex;
use super::material::template::{self, Generated};
use super::material::{MaterialSet, VariantKey, VariantMode};
pub(crate) use super::pass_states::{depth, target, GeoPass, LightPipe};
use super::pass_states::{geo_outputs, light_stages};
use super::targets::*;
use super::upload::Cull;
use super::wgsl_check::check;
use crate::gpu::bindings;
use crate::gpu::context::GpuContext;
use std::collections::HashMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct GeoKey {
    pub pass: GeoPass,
    pub variant: VariantKey,
    pub cull: Cull,
    /// Forward light-loop bound (0 for passes without the loop).
    pub lights: u32,
}

/// Bind group layouts shared by all pipelines.
pub(crate) struct Layouts {
    pub g0: wgpu::BindGroupLayout,
    pub g1_gbuffer: wgpu::BindGroupLayout,
    pub g1_light_buffers: wgpu::BindGroupLayout,
    /// Group 2 of the compute light pass: the light buffers and the scene
    /// (written), the geometry pass's emission (read).
    pub g2_light_compute: wgpu::BindGroupLayout,
    /// Group 2 of the compute AUX resolve: AUX.depth, normal, position and
    /// motion (written, in [`AUX_COMPUTE_FORMATS`]); `None` where the adapter
    /// cannot store to them (the resolve is then a fragment pass).
    pub g2_aux_compute: Option<wgpu::BindGroupLayout>,
    /// Group 2 of the compute AUX resolve's second half: AUX.albedo (its raw
    /// twin), material and specular (written, in [`AUX_B_COMPUTE_FORMATS`]);
    /// `None` where the adapter cannot store to them (that half is then drawn).
    pub g2_aux_b_compute: Option<wgpu::BindGroupLayout>,
}

/// The formats the compute AUX resolve stores (`fx_cs_aux_a`, bindings 4–7 of
/// group 2): AUX.depth, normal, position and motion, as `published_aux` makes
/// them where the adapter renders `R32Float`.
pub(crate) const AUX_COMPUTE_FORMATS: [wgpu::TextureFormat; 4] = [
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rg16Float,
];

/// The formats the compute AUX resolve's second half stores (`fx_cs_aux_b`,
/// bindings 8–10 of group 2): AUX.albedo through the raw twin of its
/// `Rgba8UnormSrgb` (a storage texture cannot be sRGB: the shader encodes, and
/// the twin is copied into the sRGB image), material and specular, as
/// `published_aux` makes them.
pub(crate) const AUX_B_COMPUTE_FORMATS: [wgpu::TextureFormat; 3] = [
    wgpu::TextureFormat::Rgba8Unorm,
    wgpu::TextureFormat::Rgba8Unorm,
    wgpu::TextureFormat::R16Float,
];

/// The stages of group 0 and of the G-buffer group: the render stages and the
/// compute light pass.
const ALL_STAGES: wgpu::ShaderStages =
    wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE);

/// A read-only storage buffer of group 0 (every stage).
pub(crate) fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    bindings::storage_entry(binding, ALL_STAGES)
}

/// A 2D texture read by the fragment stage (and the compute light pass).
pub(crate) fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    let d2 = wgpu::TextureViewDimension::D2;
    let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    bindings::texture_entry(binding, stages, sample_type, d2)
}

/// Whether the adapter can store to every format of the compute AUX resolve
/// (and renders `R32Float`, so AUX.depth has that format).
pub(crate) fn aux_compute_supported(ctx: &GpuContext) -> bool {
    AUX_COMPUTE_FORMATS
        .iter()
        .all(|f| ctx.format_support(*f).storage)
        && ctx.format_support(wgpu::TextureFormat::R32Float).render
}

/// Whether the adapter can store to every format of the compute AUX resolve's
/// second half (albedo, material, specular).
pub(crate) fn aux_b_compute_supported(ctx: &GpuContext) -> bool {
    AUX_B_COMPUTE_FORMATS
        .iter()
        .all(|f| ctx.format_support(*f).storage)
}

/// A write-only `Rgba16Float` storage texture of the compute light pass.
fn storage_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    storage_texture_entry_of(binding, LIGHT_FORMAT)
}

/// A write-only storage texture of `format` of a compute pass.
fn storage_texture_entry_of(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

impl Layouts {
    /// Group 0 (frame, material info, instances, lights, visible light indices),
    /// group 1 of the light passes (G-buffer) and of the light pre-pass final pass
    /// (light buffers); group 2 of the compute AUX resolve's halves where the
    /// adapter can store to their formats (`aux_compute`: first, second).
    pub fn new(device: &wgpu::Device, aux_compute: (bool, bool)) -> Layouts {
        let env = super::environment::EnvironmentLighting::g0_layout_entries();
        let g0 = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred group 0 (frame, materials, instances, lights)"),
            entries: &[
                bindings::uniform_entry(0, ALL_STAGES),
                storage_entry(1),
                storage_entry(2),
                storage_entry(3),
                storage_entry(4),
                storage_entry(5),
                storage_entry(6),
                // 8–10: shadow maps, sampler, layers
                super::shadow_pass::g0_layout_entries()[0],
                super::shadow_pass::g0_layout_entries()[1],
                super::shadow_pass::g0_layout_entries()[2],
                // 11–15: the environment's maps, sampler and uniform
                env[0],
                env[1],
                env[2],
                env[3],
                env[4],
            ],
        });
        let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
        let g1_gbuffer = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred group 1 (G-buffer)"),
            entries: &[
                texture_entry(0, wgpu::TextureSampleType::Depth),
                texture_entry(1, unfilterable),
                texture_entry(2, unfilterable),
                texture_entry(3, unfilterable),
                texture_entry(4, unfilterable),
                texture_entry(5, unfilterable),
            ],
        });
        let g1_light_buffers = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred group 1 (light buffers)"),
            entries: &[
                texture_entry(0, unfilterable),
                texture_entry(1, unfilterable),
            ],
        });
        let g2_light_compute = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deferred group 2 (compute light pass)"),
            entries: &[
                storage_texture_entry(0),
                storage_texture_entry(1),
                storage_texture_entry(2),
                texture_entry(3, unfilterable),
            ],
        });
        let g2_aux_compute = aux_compute.0.then(|| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("deferred group 2 (compute AUX resolve)"),
                entries: &[
                    storage_texture_entry_of(4, AUX_COMPUTE_FORMATS[0]),
                    storage_texture_entry_of(5, AUX_COMPUTE_FORMATS[1]),
                    storage_texture_entry_of(6, AUX_COMPUTE_FORMATS[2]),
                    storage_texture_entry_of(7, AUX_COMPUTE_FORMATS[3]),
                ],
            })
        });
        let g2_aux_b_compute = aux_compute.1.then(|| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("deferred group 2 (compute AUX resolve, albedo/material/specular)"),
                entries: &[
                    storage_texture_entry_of(8, AUX_B_COMPUTE_FORMATS[0]),
                    storage_texture_entry_of(9, AUX_B_COMPUTE_FORMATS[1]),
                    storage_texture_entry_of(10, AUX_B_COMPUTE_FORMATS[2]),
                ],
            })
        });
        Layouts {
            g0,
            g1_gbuffer,
            g1_light_buffers,
            g2_light_compute,
            g2_aux_compute,
            g2_aux_b_compute,
        }
    }
}

pub(crate) struct Pipelines {
    pub mode: VariantMode,
    normal_encoding: u32,
    modules: HashMap<(VariantKey, u32), wgpu::ShaderModule>,
    light_module: Option<wgpu::ShaderModule>,
    geo: HashMap<GeoKey, wgpu::RenderPipeline>,
    light: HashMap<LightPipe, wgpu::RenderPipeline>,
    /// Pipelines and shader modules created so far.
    pub pipelines_created: usize,
    pub modules_created: usize,
}

/// A module of generated WGSL, [checked](check) first.
fn shader_module(
    ctx: &GpuContext,
    label: &str,
    wgsl: String,
) -> Result<wgpu::ShaderModule, String> {
    check(label, &wgsl)?;
    ctx.scoped(label, |device| {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(wgsl.into()),
        })
    })
    .map_err(|e| e.to_string())
}

impl Pipelines {
    pub fn new(mode: VariantMode, normal_encoding: u32) -> Pipelines {
        Pipelines {
            mode,
            normal_encoding,
            modules: HashMap::new(),
            light_module: None,
            geo: HashMap::new(),
            light: HashMap::new(),
            pipelines_created: 0,
            modules_created: 0,
        }
    }

    fn module(
        &mut self,
        ctx: &GpuContext,
        set: &MaterialSet,
        variant: VariantKey,
        lights: u32,
    ) -> Result<(wgpu::ShaderModule, Vec<(String, f64)>), String> {
        // One module per feature set and light count only when preprocessing.
        let (module_key, light_key) = match self.mode {
            VariantMode::Preprocess => (variant, lights),
            _ => (
                VariantKey {
                    features: 0,
                    ..variant
                },
                0,
            ),
        };
        if !self.modules.contains_key(&(module_key, light_key)) {
            let Generated { wgsl, .. } = template::geometry_module(
                set,
                module_key,
                self.mode,
                lights,
                self.normal_encoding,
            )?;
            let label = format!(
                "deferred geometry shaders ({} + {}, {}, features {:#x}, {} lights)",
                set.surfaces[variant.surface].name,
                set.lightings[variant.lighting].name,
                self.mode,
                module_key.features,
                light_key
            );
            log::debug!("{label}: {} bytes of WGSL", wgsl.len());
            let module = shader_module(ctx, &label, wgsl)?;
            self.modules_created += 1;
            self.modules.insert((module_key, light_key), module);
        }
        let module = self.modules[&(module_key, light_key)].clone();
        // The constants of this variant (override mode).
        let constants = match self.mode {
            VariantMode::Override => {
                let s = &set.surfaces[variant.surface];
                let mut c: Vec<(String, f64)> = s
                    .flags
                    .iter()
                    .enumerate()
                    .map(|(i, f)| {
                        (
                            f.clone(),
                            if variant.features & (1 << i) != 0 {
                                1.0
                            } else {
                                0.0
                            },
                        )
                    })
                    .collect();
                c.push(("FX_LIGHT_COUNT".into(), f64::from(lights.max(1))));
                c
            }
            _ => Vec::new(),
        };
        Ok((module, constants))
    }

    /// The geometry pipeline `key`, created if needed.
    pub fn geometry(
        &mut self,
        ctx: &GpuContext,
        set: &MaterialSet,
        layouts: &Layouts,
        material_layout: &wgpu::BindGroupLayout,
        params_layout: &wgpu::BindGroupLayout,
        key: GeoKey,
    ) -> Result<&wgpu::RenderPipeline, String> {
        if !self.geo.contains_key(&key) {
            let (module, constants) = self.module(ctx, set, key.variant, key.lights)?;
            let (fs, targets, depth_state) = geo_outputs(key.pass);
            let g1 = (key.pass == GeoPass::LppFinal).then_some(&layouts.g1_light_buffers);
            let groups = [
                Some(&layouts.g0),
                g1,
                Some(material_layout),
                Some(params_layout),
            ];
            let attrs = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x2, 4 => Float32x4, 5 => Float32x4];
            let buffers = [Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attrs,
            })];
            let label = format!("deferred pipeline {key:?}");
            let pipeline = create(
                ctx,
                &label,
                &module,
                ("fx_vs_geometry", fs),
                &buffers,
                &targets,
                depth_state,
                key.cull.primitive(),
                &groups,
                &constants,
            )?;
            self.pipelines_created += 1;
            self.geo.insert(key, pipeline);
        }
        Ok(&self.geo[&key])
    }

    /// The light module (light passes, composition, resolve; the compute light
    /// pass too), generated and compiled on first use.
    pub fn light_module(
        &mut self,
        ctx: &GpuContext,
        set: &MaterialSet,
    ) -> Result<wgpu::ShaderModule, String> {
        if let Some(module) = &self.light_module {
            return Ok(module.clone());
        }
        let Generated { wgsl, .. } = template::light_module(set, self.normal_encoding)?;
        let label = format!(
            "deferred light shaders ({} lighting models)",
            set.lightings.len()
        );
        let module = shader_module(ctx, &label, wgsl)?;
        self.modules_created += 1;
        self.light_module = Some(module.clone());
        Ok(module)
    }

    /// The light-module pipeline `which`, created if needed.
    pub fn light(
        &mut self,
        ctx: &GpuContext,
        set: &MaterialSet,
        layouts: &Layouts,
        params_layout: &wgpu::BindGroupLayout,
        aux_formats: &[(String, wgpu::TextureFormat)],
        which: LightPipe,
    ) -> Result<&wgpu::RenderPipeline, String> {
        if !self.light.contains_key(&which) {
            let module = self.light_module(ctx, set)?;
            let volume_attrs = wgpu::vertex_attr_array![0 => Float32x3];
            let volume_vb = [Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &volume_attrs,
            })];
            let stages = light_stages(which, aux_formats, &volume_vb);
            let groups = [
                Some(&layouts.g0),
                Some(&layouts.g1_gbuffer),
                None,
                Some(params_layout),
            ];
            let label = format!("deferred pipeline {which:?}");
            let pipeline = create(
                ctx,
                &label,
                &module,
                (stages.vs, stages.fs),
                stages.buffers,
                &stages.targets,
                stages.depth_state,
                stages.primitive,
                &groups,
                &[],
            )?;
            self.pipelines_created += 1;
            self.light.insert(which, pipeline);
        }
        Ok(&self.light[&which])
    }

    pub fn geo_cached(&self, key: &GeoKey) -> &wgpu::RenderPipeline {
        &self.geo[key]
    }

    pub fn light_cached(&self, which: LightPipe) -> &wgpu::RenderPipeline {
        &self.light[&which]
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn create(
    ctx: &GpuContext,
    label: &str,
    module: &wgpu::ShaderModule,
    (vs, fs): (&str, &str),
    buffers: &[Option<wgpu::VertexBufferLayout>],
    targets: &[Option<wgpu::ColorTargetState>],
    depth_stencil: Option<wgpu::DepthStencilState>,
    primitive: wgpu::PrimitiveState,
    groups: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(String, f64)],
) -> Result<wgpu::RenderPipeline, String> {
    let constants: Vec<(&str, f64)> = constants.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    ctx.scoped(label, |device| {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: groups,
            immediate_size: 0,
        });
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vs),
                compilation_options: options.clone(),
                buffers,
            },
            primitive,
            depth_stencil,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: options,
                targets,
            }),
            multiview_mask: None,
            cache: ctx.pipeline_cache.as_ref(),
        })
    })
    .map_err(|e| e.to_string())
}
