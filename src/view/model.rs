//! What the panel shows ([`Model`]): a copy of the effect's parameters, the
//! pass list with its times, what is shown and how it plays, made before each
//! frame from the content, the effect and the view state ([`Model::new`]).
//! The times change every frame: they are refreshed twice a second
//! ([`FIGURES_EVERY`]), readable, and the panel is not drawn again for them every
//! frame ([`super::panel_cache`]).

use super::content::Content;
use super::fps::FpsReading;
use super::fx::Fx;
use super::inspect::{pass_rows, PassRow};
use super::ui_state::{Figures, UiState};
use crate::gpu::executor::{Engine, ParamInfo, Prepared};
use crate::graph::EffectParam;
use crate::script::types::Format;
use std::time::{Duration, Instant};

/// How often the panel's figures (frame and pass times, fps) are refreshed.
pub const FIGURES_EVERY: Duration = Duration::from_millis(500);

/// What the panel shows (a copy, made before the frame).
pub struct Model {
    /// What is shown (the file, the frame, the scene).
    pub caption: String,
    pub adapter: String,
    pub effect_params: Vec<EffectParam>,
    pub params: Vec<ParamInfo>,
    /// Per pass parameter: the value a reset gives, and whether it is set.
    pub defaults: Vec<Vec<f64>>,
    pub set: Vec<bool>,
    pub rows: Vec<PassRow>,
    /// GPU times have been read.
    pub timed: bool,
    pub aux: Vec<(String, Format)>,
    pub output_format: Option<Format>,
    pub shown_format: Option<Format>,
    pub playing: Option<bool>,
    pub scene: bool,
    pub frame_ms: Option<f64>,
    /// Frames per second over the last second, with the mean frame time.
    pub fps: Option<FpsReading>,
    /// The output's size, which the image area shows.
    pub image_size: (f32, f32),
    pub set_args: Option<String>,
}

impl Model {
    /// The parameters and passes of `fx` as planned in `prepared`, for a panel
    /// of an application's own ([`super::panel::params_section`],
    /// [`super::panel::passes_section`]); what is shown and the times are left
    /// empty.
    pub fn for_effect(fx: &Fx, prepared: Option<&Prepared>, adapter: &str) -> Model {
        let params = prepared.map(|p| p.params()).unwrap_or_default();
        Model {
            caption: String::new(),
            adapter: adapter.to_string(),
            effect_params: fx.effect_params().to_vec(),
            defaults: params.iter().map(|p| fx.pass_default(p)).collect(),
            set: params.iter().map(|p| fx.pass_is_set(&p.name)).collect(),
            params,
            rows: prepared.map(pass_rows).unwrap_or_default(),
            timed: prepared.is_some_and(|p| !p.gpu_timings().is_empty()),
            aux: Vec::new(),
            output_format: prepared.map(|p| p.plan.output.format),
            shown_format: None,
            playing: None,
            scene: false,
            frame_ms: None,
            fps: None,
            image_size: (1.0, 1.0),
            set_args: None,
        }
    }

    /// The panel's copy of what `content`, `fx` and `ui` show on `engine`;
    /// `frame_ms`: the last frame's time. Refreshes `ui.figures` when due.
    pub fn new(
        content: &mut Content,
        fx: &Fx,
        ui: &mut UiState,
        engine: &Engine,
        frame_ms: Option<f64>,
    ) -> Model {
        let mut m = Model::for_effect(fx, content.prepared_ref(), &engine.ctx.info.name);
        let figures = refresh_figures(ui, &m.rows, frame_ms);
        for (r, ms) in m.rows.iter_mut().zip(&figures.gpu_ms) {
            r.gpu_ms = *ms;
        }
        (m.frame_ms, m.fps) = (figures.frame_ms, figures.fps);
        m.shown_format = content.shown(engine, &ui.inspect.target).map(|(_, f)| f);
        m.caption = content.caption();
        m.aux = content.aux().into_iter().map(|(n, _, f)| (n, f)).collect();
        m.output_format = content.output_format();
        m.playing = content.playing();
        m.scene = matches!(content, Content::Scene(_));
        m.image_size = content.image_size().unwrap_or((1.0, 1.0));
        m.set_args = ui.copied.clone();
        m
    }
}

/// The figures to show: those of `ui`, made again when older than
/// [`FIGURES_EVERY`] or for another pass list.
fn refresh_figures<'u>(
    ui: &'u mut UiState,
    rows: &[PassRow],
    frame_ms: Option<f64>,
) -> &'u Figures {
    let stale = ui
        .figures
        .as_ref()
        .is_none_or(|f| f.at.elapsed() >= FIGURES_EVERY || f.gpu_ms.len() != rows.len());
    if stale {
        ui.figures = Some(Figures {
            at: Instant::now(),
            frame_ms,
            gpu_ms: rows.iter().map(|r| r.gpu_ms).collect(),
            fps: ui.fps.reading(),
        });
    }
    ui.figures.as_ref().expect("set above")
}
