//! Encoding one pass of a frame: the views of its sources, its bind group (from
//! the pass's cache, made on a miss) and its render pass.

use super::pool::{PooledTexture, TexturePool};
use super::record::{GpuPass, Source};
use super::{CachedPipeline, ExecError};
use crate::gpu::context::GpuContext;
use crate::gpu::fullscreen::begin_color_pass;

/// Bind groups kept per pass: enough for feedback rings and a few caller views.
const BIND_GROUPS_PER_PASS: usize = 8;

/// What a bound texture is, for the bind group cache.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum BindKey {
    Pooled(u64),
    Caller(wgpu::TextureView),
}

/// Where a frame's textures are: the pool with the plan's slots, the feedback
/// rings, and the caller's views.
#[derive(Clone, Copy)]
pub(super) struct FrameTextures<'v> {
    pub pool: &'v TexturePool,
    pub slots: &'v [Option<usize>],
    pub rings: &'v [Vec<PooledTexture>],
    pub ring_head: &'v [usize],
    pub caller: &'v [wgpu::TextureView],
}

/// The view a source names this frame, with its bind-group key.
pub(super) fn source_view<'v>(
    source: &Source,
    format: Option<wgpu::TextureFormat>,
    tex: FrameTextures<'v>,
) -> Result<(BindKey, &'v wgpu::TextureView), ExecError> {
    view_of(source, format, tex, PooledTexture::view)
}

/// The view a pass writes `target` through this frame: level 0 of a
/// mipmapped texture.
pub(super) fn target_view<'v>(
    target: &Source,
    format: Option<wgpu::TextureFormat>,
    tex: FrameTextures<'v>,
) -> Result<(BindKey, &'v wgpu::TextureView), ExecError> {
    view_of(target, format, tex, PooledTexture::target_view)
}

/// The view `pick` chooses of the texture `source` names this frame.
fn view_of<'v>(
    source: &Source,
    format: Option<wgpu::TextureFormat>,
    tex: FrameTextures<'v>,
    pick: for<'t> fn(
        &'t PooledTexture,
        Option<wgpu::TextureFormat>,
    ) -> Option<&'t wgpu::TextureView>,
) -> Result<(BindKey, &'v wgpu::TextureView), ExecError> {
    let FrameTextures {
        pool,
        slots,
        rings,
        ring_head,
        caller,
    } = tex;
    let pooled = |t: &'v PooledTexture| {
        pick(t, format)
            .map(|v| (BindKey::Pooled(t.id), v))
            .ok_or_else(|| {
                ExecError::Input(format!(
                    "no {format:?} view of a {} texture on this backend",
                    t.desc.format
                ))
            })
    };
    match source {
        Source::Caller(i) => Ok((BindKey::Caller(caller[*i].clone()), &caller[*i])),
        Source::Slot(s) => pooled(pool.get(slots[*s].expect("allocated before use"))),
        Source::Ring { ring, back } => {
            let r = &rings[*ring];
            pooled(&r[(ring_head[*ring] + *back as usize) % r.len()])
        }
    }
}

/// The views of the textures a pass reads this frame, in binding order, with
/// their bind-group keys.
pub(super) fn bound_views<'v>(
    gp: &GpuPass,
    tex: FrameTextures<'v>,
) -> Result<Vec<(BindKey, &'v wgpu::TextureView)>, ExecError> {
    gp.textures
        .iter()
        .map(|(_, source, format)| source_view(source, *format, tex))
        .collect()
}

/// A bind group of a pass: its textures (`views`, in the order of
/// `gp.textures`), samplers and uniform, and a storage target when given.
pub(super) fn create_bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    gp: &GpuPass,
    views: &[(BindKey, &wgpu::TextureView)],
    storage: Option<(u32, &wgpu::TextureView)>,
) -> wgpu::BindGroup {
    let mut entries: Vec<wgpu::BindGroupEntry> = Vec::with_capacity(gp.textures.len() + 4);
    for ((binding, _, _), (_, v)) in gp.textures.iter().zip(views) {
        entries.push(wgpu::BindGroupEntry {
            binding: *binding,
            resource: wgpu::BindingResource::TextureView(v),
        });
    }
    for (b, s) in &gp.samplers {
        entries.push(wgpu::BindGroupEntry {
            binding: *b,
            resource: wgpu::BindingResource::Sampler(s),
        });
    }
    if let Some(u) = &gp.uniform {
        entries.push(wgpu::BindGroupEntry {
            binding: u.binding,
            resource: u.buffer.as_entire_binding(),
        });
    }
    if let Some((binding, v)) = storage {
        entries.push(wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        });
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The index in the pass's cache of its bind group for this frame's textures,
/// made now on a miss; with the number of bind groups created (0 or 1).
pub(super) fn bind_group(
    gp: &mut GpuPass,
    device: &wgpu::Device,
    tex: FrameTextures,
) -> Result<(usize, u64), ExecError> {
    let views = bound_views(gp, tex)?;
    let key: Vec<BindKey> = views.iter().map(|(k, _)| k.clone()).collect();
    if let Some(i) = gp.bind_groups.iter().position(|(k, _)| *k == key) {
        return Ok((i, 0));
    }
    let label = format!("{} bind group", gp.path);
    let layout = &gp.pipeline.as_ref().expect("a fragment pass").layout;
    let bg = create_bind_group(device, &label, layout, gp, &views, None);
    if gp.bind_groups.len() == BIND_GROUPS_PER_PASS {
        gp.bind_groups.remove(0);
    }
    gp.bind_groups.push((key, bg));
    Ok((gp.bind_groups.len() - 1, 1))
}

/// Record one pass with `pipeline` (the pass's, or its BGRA twin's): a render pass
/// drawing the fullscreen triangle into its target.
/// Returns the number of bind groups created.
pub(super) fn encode_pass(
    gp: &mut GpuPass,
    pipeline: &CachedPipeline,
    ctx: &GpuContext,
    tex: FrameTextures,
    encoder: &mut wgpu::CommandEncoder,
    timestamps: Option<wgpu::RenderPassTimestampWrites>,
) -> Result<u64, ExecError> {
    let (bg, created) = bind_group(gp, &ctx.device, tex)?;
    let gp = &*gp;
    let (_, target) = target_view(&gp.target, gp.target_format, tex)?;
    // SAFETY: the fullscreen triangle writes every pixel of the target.
    let load = wgpu::LoadOp::DontCare(unsafe { wgpu::LoadOpDontCare::enabled() });
    let mut rp = begin_color_pass(encoder, &gp.path, target, load, timestamps);
    rp.set_pipeline(&pipeline.pipeline);
    rp.set_bind_group(0, &gp.bind_groups[bg].1, &[]);
    rp.draw(0..3, 0..1);
    Ok(created)
}
