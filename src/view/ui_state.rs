//! What the viewer shows and how, besides the content: the view (fit, zoom,
//! split, exposure), what is inspected, the last error and message, and the
//! figures the panel shows. The panel ([`super::panel`]) edits it; the window
//! loop reads it each frame.

use super::fps::{FpsCounter, FpsReading};
use super::inspect::Inspect;
use std::time::Instant;

/// Width of the control panel, in points.
pub const PANEL_WIDTH: f32 = 360.0;

/// What the viewer shows and how, besides the content.
pub struct UiState {
    pub panel: bool,
    /// Fit the image to the area (else `zoom` with `center`).
    pub fit: bool,
    /// Screen pixels per image pixel when not fitting.
    pub zoom: f32,
    /// The image point (in its pixels) at the centre of the area.
    pub center: [f32; 2],
    /// Image x (0..1) of the before/after split, when shown.
    pub split: Option<f32>,
    /// Exposure (stops) of linear-light images.
    pub exposure: f32,
    pub mark_clipping: bool,
    /// Record the effect of a still or a scene every frame (for its GPU times).
    pub continuous: bool,
    pub inspect: Inspect,
    /// The last compile or run error (rendered diagnostics), shown until it is fixed.
    pub error: Option<String>,
    /// The last message.
    pub status: String,
    /// The last "copy as --set" text.
    pub copied: Option<String>,
    /// The image area of the last frame (surface pixels: x, y, width, height).
    pub area: [u32; 4],
    /// The frame and pass times the panel shows.
    pub figures: Option<Figures>,
    /// The frames shown over the last second (the panel's fps readout).
    pub fps: FpsCounter,
}

/// The mouse over the image area.
#[derive(Debug, Default, Clone)]
pub struct ImageInput {
    /// The image area in points: x, y, width, height.
    pub area: [f32; 4],
    /// Dragged this frame, in pixels.
    pub drag: [f32; 2],
    /// With the primary button (else the secondary or middle one).
    pub primary: bool,
    /// Wheel notches (positive: away from the user, zoom in).
    pub scroll: f32,
    /// The pointer, in pixels.
    pub hover: Option<[f32; 2]>,
    pub double_click: bool,
}

/// Times shown in the panel, refreshed twice a second.
pub struct Figures {
    pub at: Instant,
    pub frame_ms: Option<f64>,
    pub gpu_ms: Vec<Option<f64>>,
    /// Frames per second and the mean frame time over the last second.
    pub fps: Option<FpsReading>,
}

impl Default for UiState {
    fn default() -> Self {
        UiState {
            panel: true,
            fit: true,
            zoom: 1.0,
            center: [0.0, 0.0],
            split: None,
            exposure: 0.0,
            mark_clipping: false,
            continuous: false,
            inspect: Inspect::default(),
            error: None,
            status: String::new(),
            copied: None,
            area: [0, 0, 0, 0],
            figures: None,
            fps: FpsCounter::default(),
        }
    }
}

impl UiState {
    /// Where an image of `size` pixels is drawn in the image area (fit, or the
    /// zoom around the centre point), on whole pixels: x, y, width, height.
    pub fn image_rect(&self, (iw, ih): (f32, f32)) -> [f32; 4] {
        let [ax, ay, aw, ah] = self.area.map(|v| v as f32);
        let (cx, cy) = (ax + aw / 2.0, ay + ah / 2.0);
        if self.fit {
            let s = (aw / iw).min(ah / ih);
            let (w, h) = (iw * s, ih * s);
            return [(cx - w / 2.0).round(), (cy - h / 2.0).round(), w, h];
        }
        let z = self.zoom;
        [
            (cx - self.center[0] * z).round(),
            (cy - self.center[1] * z).round(),
            iw * z,
            ih * z,
        ]
    }

    /// Show an image of `size` pixels at 1:1 around its centre.
    pub fn one_to_one(&mut self, (iw, ih): (f32, f32)) {
        self.fit = false;
        self.zoom = 1.0;
        self.center = [iw / 2.0, ih / 2.0];
    }

    /// Zoom an image of `size` pixels by `factor` around `at` (area pixels;
    /// `None`: the area's centre); the image point under `at` stays there.
    pub fn zoom_by(&mut self, (iw, ih): (f32, f32), factor: f32, at: Option<[f32; 2]>) {
        let [ax, ay, aw, ah] = self.area.map(|v| v as f32);
        if self.fit {
            self.zoom = (aw / iw).min(ah / ih).max(1e-3);
            self.center = [iw / 2.0, ih / 2.0];
            self.fit = false;
        }
        let at = at.unwrap_or([ax + aw / 2.0, ay + ah / 2.0]);
        let z0 = self.zoom;
        let z1 = (z0 * factor).clamp(1.0 / 64.0, 64.0);
        let origin = [
            ax + aw / 2.0 - self.center[0] * z0,
            ay + ah / 2.0 - self.center[1] * z0,
        ];
        let p = [(at[0] - origin[0]) / z0, (at[1] - origin[1]) / z0];
        let new_origin = [at[0] - p[0] * z1, at[1] - p[1] * z1];
        self.zoom = z1;
        self.center = [
            (ax + aw / 2.0 - new_origin[0]) / z1,
            (ay + ah / 2.0 - new_origin[1]) / z1,
        ];
    }

    /// Mouse input over an image of `size` pixels (none shown yet: `None`):
    /// drag pans, the wheel zooms at the pointer, a double click toggles fit.
    /// True when the view changed.
    pub fn apply_image_input(&mut self, input: &ImageInput, size: Option<(f32, f32)>) -> bool {
        let mut changed = false;
        if input.drag != [0.0, 0.0] {
            if let (true, Some(size)) = (self.fit, size) {
                self.zoom_by(size, 1.0, None);
            }
            self.center[0] -= input.drag[0] / self.zoom;
            self.center[1] -= input.drag[1] / self.zoom;
            changed = true;
        }
        if input.scroll != 0.0 {
            if let Some(size) = size {
                self.zoom_by(size, 1.25f32.powf(input.scroll), input.hover);
            }
            changed = true;
        }
        if input.double_click {
            self.fit = !self.fit;
            changed = true;
        }
        changed
    }
}
