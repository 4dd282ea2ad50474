//! Mip chains: after a pass writes a texture that an input reads with
//! `NAME.MIPMAP = true` (a plan value whose descriptor has `mips > 1`), each
//! level below 0 is drawn from the level above it, in the same command encoder,
//! before any later pass reads it. One render pass per level, labelled
//! `PASS mip N`, with `shaders/engine/_mipmap.wgsl`: the bilinear blit RetroArch
//! and librashader make their chains with (a 2 x 2 box where a side halves).
//!
//! Made once per engine, on the first mipmapped texture: the pipelines (one per
//! target format) and a bind group per (texture, level), kept while the texture
//! is (pooled textures are recycled, so their bind groups are too).

use super::pool::PooledTexture;
use super::record::Prepared;
use super::Engine;
use crate::gpu::bindings::texture_entry;
use crate::gpu::fullscreen::{begin_color_pass, fullscreen_pipeline};
use crate::graph::plan::Resource;
use std::collections::HashMap;

/// The built-in downsampling shader.
const MIPMAP_WGSL: &str = include_str!("../../../shaders/engine/_mipmap.wgsl");

/// Bind groups kept before the cache is emptied (textures of sizes no longer
/// used leave theirs behind).
const MAX_GROUPS: usize = 256;

/// The downsampling pipelines and bind groups of one engine.
pub(super) struct MipChains {
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
    /// (texture id, level read) → its bind group.
    groups: HashMap<(u64, u32), wgpu::BindGroup>,
}

impl MipChains {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fxgraph mipmap"),
            source: wgpu::ShaderSource::Wgsl(MIPMAP_WGSL.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fxgraph mipmap bind group layout"),
            entries: &[texture_entry(
                0,
                wgpu::ShaderStages::FRAGMENT,
                // Read with textureLoad: every format, filterable or not.
                wgpu::TextureSampleType::Float { filterable: false },
                wgpu::TextureViewDimension::D2,
            )],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("fxgraph mipmap pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        MipChains {
            module,
            layout,
            pipeline_layout,
            pipelines: HashMap::new(),
            groups: HashMap::new(),
        }
    }

    /// Draw levels 1 and below of `t` from its level 0 into `encoder`; `path`
    /// names the pass that wrote level 0 (labels). `vs` is the full-screen
    /// vertex stage. Returns the number of bind groups created.
    pub fn generate(
        &mut self,
        device: &wgpu::Device,
        vs: &wgpu::ShaderModule,
        encoder: &mut wgpu::CommandEncoder,
        t: &PooledTexture,
        path: &str,
    ) -> u64 {
        let format = t.natural_format;
        if !self.pipelines.contains_key(&format) {
            let p = fullscreen_pipeline(
                device,
                &format!("fxgraph mipmap {format:?}"),
                Some(&self.pipeline_layout),
                (vs, "vs_main"),
                (&self.module, "fs_main"),
                format,
                None,
            );
            self.pipelines.insert(format, p);
        }
        if self.groups.len() > MAX_GROUPS {
            self.groups.clear();
        }
        let mut created = 0;
        for level in 1..t.levels.len() as u32 {
            let group = self.groups.entry((t.id, level - 1)).or_insert_with(|| {
                created += 1;
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("fxgraph mipmap level {} of #{}", level - 1, t.id)),
                    layout: &self.layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&t.levels[level as usize - 1]),
                    }],
                })
            });
            // SAFETY: the full-screen triangle writes every texel of the level.
            let load = wgpu::LoadOp::DontCare(unsafe { wgpu::LoadOpDontCare::enabled() });
            let label = format!("{path} mip {level}");
            let mut rp = begin_color_pass(encoder, &label, &t.levels[level as usize], load, None);
            rp.set_pipeline(&self.pipelines[&format]);
            rp.set_bind_group(0, &*group, &[]);
            rp.draw(0..3, 0..1);
        }
        created
    }
}

impl Prepared {
    /// After pass `pass`: the mip chain of its output, where an input reads it
    /// mipmapped (`mips > 1`). Returns the number of bind groups created.
    pub(super) fn make_mips(
        &self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
        pass: usize,
    ) -> u64 {
        let Resource::Value(v) = self.plan.passes[pass].output else {
            return 0;
        };
        let value = &self.plan.values[v];
        if value.desc.mips < 2 {
            return 0;
        }
        let Some(i) = self.slots[value.slot] else {
            return 0;
        };
        let device = &engine.ctx.device;
        let chains = engine.mips.get_or_insert_with(|| MipChains::new(device));
        let path = &self.plan.passes[pass].path;
        chains.generate(device, &engine.vs, encoder, engine.pool.get(i), path)
    }
}
