//! What the viewer shows: still images, a sequence or a scene, behind one
//! interface (plan, record a frame, the output, the "before" image, AUX images).

use super::fx::Fx;
use super::playback::Playback;
use super::scene_view::SceneView;
use super::stills::Stills;
use crate::app::RunError;
use crate::gpu::executor::{Engine, Prepared};
use crate::script::types::Format;

pub enum Content {
    Stills(Box<Stills>),
    Playback(Box<Playback>),
    Scene(Box<SceneView>),
}

impl Content {
    /// Plan `fx`'s effect for what is shown (at the start, after a reload, after a
    /// change of the passes, a new image size, a new scene size).
    pub fn prepare(&mut self, engine: &mut Engine, fx: &mut Fx) -> Result<(), RunError> {
        match self {
            Content::Stills(s) => s.prepare(engine, fx.effect_mut()?),
            Content::Playback(p) => {
                let at = p.shown().unwrap_or(0);
                p.seek(engine, fx, at)
            }
            Content::Scene(s) => s.prepare(engine, fx),
        }
    }

    /// Does the shown image need a new plan (another size or format)?
    pub fn needs_plan(&self) -> bool {
        match self {
            Content::Stills(s) => s.needs_plan(),
            Content::Playback(p) => p.prepared_ref().is_none(),
            Content::Scene(s) => s.needs_plan(),
        }
    }

    pub fn prepared(&mut self) -> Option<&mut Prepared> {
        match self {
            Content::Stills(s) => s.prepared(),
            Content::Playback(p) => p.prepared(),
            Content::Scene(s) => s.prepared(),
        }
    }

    pub fn prepared_ref(&self) -> Option<&Prepared> {
        match self {
            Content::Stills(s) => s.prepared_ref(),
            Content::Playback(p) => p.prepared_ref(),
            Content::Scene(s) => s.prepared_ref(),
        }
    }

    /// Record the shown frame's effect into `encoder` (stills and scenes; a
    /// sequence runs its frames as they advance, in submissions of their own).
    pub fn record(
        &mut self,
        engine: &mut Engine,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<(), RunError> {
        match self {
            Content::Stills(s) => Ok(s.record(engine, encoder)?),
            Content::Playback(_) => Ok(()),
            Content::Scene(s) => s.record(engine, encoder),
        }
    }

    /// Does recording the frame again give the same picture (no history to feed)?
    pub fn rerecordable(&self) -> bool {
        !matches!(self, Content::Playback(_))
    }

    pub fn output(&self) -> Option<(&wgpu::Texture, Format)> {
        match self {
            Content::Stills(s) => s.output(),
            Content::Playback(p) => p.output(),
            Content::Scene(s) => s.output(),
        }
    }

    pub fn before(&mut self, engine: &Engine) -> Option<(&wgpu::Texture, Format)> {
        match self {
            Content::Stills(s) => s.before(),
            Content::Playback(p) => p.before(engine),
            Content::Scene(s) => s.before(),
        }
    }

    pub fn aux(&self) -> Vec<(String, &wgpu::Texture, Format)> {
        match self {
            Content::Stills(s) => s.aux(),
            Content::Playback(_) => Vec::new(),
            Content::Scene(s) => s.aux(),
        }
    }

    pub fn caption(&self) -> String {
        match self {
            Content::Stills(s) => s.caption(),
            Content::Playback(p) => p.caption(),
            Content::Scene(s) => s.caption(),
        }
    }

    /// The output format (what a file gets).
    pub fn output_format(&self) -> Option<Format> {
        self.output().map(|(_, f)| f)
    }
}
