//! What the viewer shows and how, besides the content: the view (fit, zoom,
//! split, exposure), what is inspected, the last error and message, and the
//! figures the panel shows. The panel ([`super::panel`]) edits it; the window
//! loop reads it each frame.

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
}

/// Times shown in the panel, refreshed twice a second.
pub struct Figures {
    pub at: Instant,
    pub frame_ms: Option<f64>,
    pub gpu_ms: Vec<Option<f64>>,
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
        }
    }
}
