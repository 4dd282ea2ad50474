//! The pieces of painting one viewer frame that need no window system: the
//! image area in surface pixels, egui's texture updates, the image bound to the
//! image pass with its placement, and the panel painted through the
//! [`PanelCache`]. The window loop calls them in order: panel (egui) → textures →
//! surface texture → image → panel → [`super::present::Presenter::encode`].

use super::inspect::shade_of;
use super::panel_cache::{PanelCache, PanelPaint};
use super::present::{Placement, Presenter, Shown};
use super::ui_state::UiState;
use crate::gpu::context::GpuContext;
use crate::gpu::fullscreen::begin_color_pass;
use crate::script::types::Format;

/// The image area `area` (points: x, y, width, height) in whole surface pixels
/// at `ppp` pixels per point, inside a `size` surface.
pub fn area_pixels(area: [f32; 4], ppp: f32, (sw, sh): (u32, u32)) -> [u32; 4] {
    let px = |v: f32, max: u32| (v * ppp).round().clamp(0.0, max as f32) as u32;
    let [x, y] = [px(area[0], sw), px(area[1], sh)];
    [
        x,
        y,
        px(area[2], sw).min(sw - x),
        px(area[3], sh).min(sh - y),
    ]
}

/// Upload egui's new and changed textures (done even when no frame is drawn);
/// returns whether any changed, and the delta whose `free` list is applied
/// after the frame ([`free_textures`]).
pub fn update_textures(
    renderer: &mut egui_wgpu::Renderer,
    ctx: &GpuContext,
    mut delta: egui::TexturesDelta,
) -> (bool, egui::TexturesDelta) {
    for (id, deltas) in &delta.set {
        for image in deltas {
            renderer.update_texture(&ctx.device, &ctx.queue, *id, image);
        }
    }
    let changed = !delta.set.is_empty();
    delta.set.clear();
    (changed, delta)
}

/// Free the egui textures a frame no longer uses.
pub fn free_textures(renderer: &mut egui_wgpu::Renderer, delta: egui::TexturesDelta) {
    for id in &delta.free {
        renderer.free_texture(id);
    }
}

/// How the image of `image_size` pixels is placed in `area` this frame (the
/// view of `ui`: fit or zoom, split, exposure, the inspected range).
pub fn placement(ui: &UiState, image_size: (f32, f32), area: [u32; 4]) -> Placement {
    Placement {
        rect: ui.image_rect(image_size),
        area,
        split: ui.split.unwrap_or(0.0),
        exposure: ui.exposure,
        range: ui.inspect.range,
        mark_clipping: ui.mark_clipping,
    }
}

/// Bind the texture shown (shaded as `ui` inspects it) and the split view's
/// "before" to the image pass; nothing when no image is shown yet.
pub fn prepare_image(
    presenter: &mut Presenter,
    ctx: &GpuContext,
    ui: &UiState,
    shown: Option<(&wgpu::Texture, Format)>,
    before: Option<(&wgpu::Texture, Format)>,
    place: &Placement,
) {
    let Some((texture, format)) = shown else {
        return;
    };
    let after = Shown {
        texture,
        format,
        shade: Some(shade_of(&ui.inspect, format)),
    };
    let before = before.map(|(texture, format)| Shown {
        texture,
        format,
        shade: None,
    });
    presenter.prepare(ctx, after, before, place);
}

/// The panel's tessellated egui output this frame.
pub struct PanelJobs<'a> {
    pub jobs: &'a [egui::ClippedPrimitive],
    pub ppp: f32,
    /// The surface's size and format.
    pub size: (u32, u32),
    pub format: wgpu::TextureFormat,
    /// Where the panel starts (surface pixels), when it is shown.
    pub panel_x: Option<u32>,
    pub textures_changed: bool,
}

/// Paint the panel: into the cache when it changed (the image pass copies the
/// cached rectangle), or not at all. Returns the cache's texture and rectangle
/// to copy, and whether egui must instead be drawn straight onto the surface.
pub fn paint_panel<'c>(
    cache: &'c mut PanelCache,
    ctx: &GpuContext,
    encoder: &mut wgpu::CommandEncoder,
    panel: &PanelJobs,
    draw_egui: impl FnOnce(&mut wgpu::RenderPass<'static>),
) -> (Option<(&'c wgpu::Texture, [u32; 4])>, bool) {
    let paint = cache.plan(
        panel.jobs,
        panel.ppp,
        panel.size,
        panel.panel_x,
        panel.textures_changed,
    );
    match paint {
        PanelPaint::Nothing => (None, false),
        PanelPaint::Direct => (None, true),
        PanelPaint::Cached { rect, redraw } => {
            let texture = cache.texture(&ctx.device, panel.size, panel.format);
            if redraw {
                let view = texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("viewer panel cache view"),
                    ..Default::default()
                });
                let clear = wgpu::LoadOp::Clear(wgpu::Color::BLACK);
                let mut rp =
                    begin_color_pass(encoder, "viewer panel", &view, clear, None).forget_lifetime();
                draw_egui(&mut rp);
            }
            (Some((texture, rect)), false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_area_is_in_whole_pixels_inside_the_surface() {
        assert_eq!(
            area_pixels([0.0, 0.0, 100.4, 50.6], 2.0, (400, 300)),
            [0, 0, 201, 101]
        );
        // Past the surface's edge: cut at it.
        assert_eq!(
            area_pixels([10.0, 5.0, 500.0, 500.0], 1.0, (400, 300)),
            [10, 5, 390, 295]
        );
    }
}
