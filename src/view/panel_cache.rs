//! The panel painted once, copied every frame: egui's triangles are drawn into a
//! texture of the window's size only when they change (a parameter moved, the
//! pointer over a button, the figures the panel refreshes twice a second), and the
//! panel's part of it is copied into each frame's surface texture. On lavapipe
//! drawing the panel costs about a sixth of a 1280x720 glow frame, a copy almost
//! nothing. Anything egui paints outside the panel (a tooltip or a menu over the
//! image) is drawn on the surface directly, every frame, as before.

use crate::gpu::transfer::texture_2d;
use egui::epaint::{ClippedPrimitive, Mesh, Primitive};

/// How the panel gets onto this frame.
pub enum PanelPaint {
    /// Nothing to paint (the panel is hidden).
    Nothing,
    /// Copy this rectangle (x, y, width, height in pixels) of the cache; it was
    /// drawn again first when `redraw`.
    Cached { rect: [u32; 4], redraw: bool },
    /// Draw egui onto the surface.
    Direct,
}

/// The last panel drawn.
#[derive(Default)]
pub struct PanelCache {
    texture: Option<wgpu::Texture>,
    drawn: Vec<(egui::Rect, Mesh)>,
}

impl PanelCache {
    /// How to paint `jobs` (in points, `ppp` pixels per point) on a surface of
    /// `size` whose panel is right of x = `panel_x` pixels (`None`: hidden);
    /// `textures_changed`: egui updated a texture this frame.
    pub fn plan(
        &mut self,
        jobs: &[ClippedPrimitive],
        ppp: f32,
        size: (u32, u32),
        panel_x: Option<u32>,
        textures_changed: bool,
    ) -> PanelPaint {
        if jobs.is_empty() {
            return PanelPaint::Nothing;
        }
        let Some(px) = panel_x.filter(|x| *x < size.0) else {
            return PanelPaint::Direct;
        };
        // Nothing may be drawn left of the panel but its edge (the separator's
        // anti-aliased half pixel): the copy starts at the leftmost vertex.
        let left = px as f32 / ppp - 1.0;
        let mut min_x = px as f32 / ppp;
        let mut meshes = Vec::with_capacity(jobs.len());
        for j in jobs {
            let Primitive::Mesh(m) = &j.primitive else {
                return PanelPaint::Direct;
            };
            let x = m
                .vertices
                .iter()
                .map(|v| v.pos.x)
                .fold(f32::INFINITY, f32::min)
                .max(j.clip_rect.min.x);
            if x < left {
                log::debug!("--view: egui paints over the image (from x = {x}): drawn directly");
                return PanelPaint::Direct;
            }
            min_x = min_x.min(x);
            meshes.push((j.clip_rect, m.clone()));
        }
        let px = ((min_x * ppp).floor().max(0.0) as u32).min(px);
        let fits = self
            .texture
            .as_ref()
            .is_some_and(|t| (t.width(), t.height()) == size);
        let redraw = !fits || textures_changed || meshes != self.drawn;
        if redraw {
            self.drawn = meshes;
        }
        PanelPaint::Cached {
            rect: [px, 0, size.0 - px, size.1],
            redraw,
        }
    }

    /// The cache texture for a surface of `size` and `format` (made on a change).
    pub fn texture(
        &mut self,
        device: &wgpu::Device,
        size: (u32, u32),
        format: wgpu::TextureFormat,
    ) -> &wgpu::Texture {
        let fits = self
            .texture
            .as_ref()
            .is_some_and(|t| (t.width(), t.height()) == size && t.format() == format);
        if !fits {
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
            let label = "viewer panel cache";
            self.texture =
                Some(device.create_texture(&texture_2d(label, size, format, usage, &[])));
        }
        self.texture.as_ref().expect("made above")
    }
}
