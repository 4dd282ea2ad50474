//! What the viewer shows: still images, a sequence or a scene, behind one
//! interface (plan, record a frame, the output, the "before" image, AUX images).

use super::command::Command;
use super::fx::Fx;
use super::inspect::{aux_range, Target};
use super::playback::Playback;
use super::scene_view::SceneView;
use super::stills::Stills;
use crate::app::RunError;
use crate::gpu::executor::{Engine, Prepared};
use crate::script::types::Format;

/// What is shown: still images, a sequence, or a scene.
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

    /// The size of the output shown, in pixels.
    pub fn image_size(&self) -> Option<(f32, f32)> {
        let (t, _) = self.output()?;
        Some((t.width() as f32, t.height() as f32))
    }

    /// Whether a sequence or a timed scene is playing (`None`: nothing plays).
    pub fn playing(&self) -> Option<bool> {
        match self {
            Content::Playback(p) => Some(p.playing),
            Content::Scene(s) if s.timed() => Some(s.clock.playing),
            _ => None,
        }
    }

    /// The texture `target` names (at full resolution) and its format.
    pub fn shown(&mut self, engine: &Engine, target: &Target) -> Option<(wgpu::Texture, Format)> {
        match target {
            Target::Output => self.output().map(|(t, f)| (t.clone(), f)),
            Target::Pass(i) => {
                let p = self.prepared_ref()?;
                let f = p.plan.passes.get(*i)?.desc.format;
                p.inspected().map(|t| (t.clone(), f))
            }
            Target::Input => self.before(engine).map(|(t, f)| (t.clone(), f)),
            Target::Aux(n) => self
                .aux()
                .into_iter()
                .find(|(m, _, _)| m == n)
                .map(|(_, t, f)| (t.clone(), f)),
        }
    }

    /// The value range an AUX image is shown in (a scene's depth: its camera's).
    pub fn aux_range(&self, name: &str) -> (f32, f32) {
        match self {
            Content::Scene(s) => aux_range(name, s.depth_range(), s.control.radius * 2.0),
            _ => (0.0, 1.0),
        }
    }

    /// Next, previous or first image or frame ([`Command::Next`],
    /// [`Command::Prev`], else the first); a sequence or a scene pauses. True
    /// when the effect must be recorded again (another image or scene frame).
    pub fn navigate(
        &mut self,
        engine: &mut Engine,
        fx: &mut Fx,
        c: Command,
    ) -> Result<bool, RunError> {
        match self {
            Content::Stills(s) => {
                let moved = match c {
                    Command::Next => s.step(1),
                    Command::Prev => s.step(-1),
                    _ => s.first(),
                };
                if moved {
                    s.load(engine)?;
                }
                Ok(moved)
            }
            Content::Playback(p) => {
                p.playing = false;
                match c {
                    Command::Next => p.step(engine, fx, 1)?,
                    Command::Prev => p.step(engine, fx, -1)?,
                    _ => p.seek(engine, fx, 0).map(|_| true)?,
                };
                Ok(false)
            }
            Content::Scene(s) => {
                s.clock.playing = false;
                let f = s.clock.frame;
                s.set_frame(match c {
                    Command::Next => f + 1,
                    Command::Prev => f.saturating_sub(1),
                    _ => 0,
                });
                Ok(true)
            }
        }
    }

    /// A paused sequence without feedback runs its frame again (to show a
    /// change; with feedback the change shows from the next frame).
    pub fn rerun_paused(&mut self, engine: &mut Engine, fx: &mut Fx) -> Result<(), RunError> {
        if let Content::Playback(p) = self {
            if !p.playing && !fx.has_feedback() {
                if let Some(at) = p.shown() {
                    p.seek(engine, fx, at)?;
                }
            }
        }
        Ok(())
    }

    /// Move on what plays, once per frame: a scene's flying camera (`dt`
    /// seconds since the last frame) and clock, a sequence's next frame. Played
    /// when due, or `scripted`: one frame further per frame shown while playing
    /// (the `first` frame shows frame 0). True when the effect must be recorded
    /// again.
    pub fn advance(
        &mut self,
        engine: &mut Engine,
        dt: f32,
        scripted: bool,
        first: bool,
    ) -> Result<bool, RunError> {
        let step = |playing: bool, due: bool| (scripted && !first && playing) || (!scripted && due);
        match self {
            Content::Scene(s) => {
                let mut cam = s.camera;
                let flown = s.control.fly(&mut cam, dt);
                if flown {
                    s.camera = cam;
                    s.camera_moved();
                }
                let c = &s.clock;
                let next = (s.timed() && step(c.playing, c.due())).then_some(c.frame + 1);
                if let Some(next) = next {
                    s.set_frame(next);
                }
                Ok(flown || next.is_some())
            }
            Content::Playback(p) => {
                if step(p.playing, p.due()) {
                    p.advance(engine)?;
                }
                Ok(false)
            }
            Content::Stills(_) => Ok(false),
        }
    }

    /// Play or pause a sequence or a timed scene.
    pub fn play_pause(&mut self) {
        match self {
            Content::Playback(p) => p.playing = !p.playing,
            Content::Scene(s) if s.timed() => {
                s.clock.playing = !s.clock.playing;
                s.set_frame(s.clock.frame);
            }
            _ => {}
        }
    }

    /// Time until the next frame of what plays is due.
    pub fn until_due(&self) -> Option<std::time::Duration> {
        match self {
            Content::Playback(p) => p.until_due(),
            Content::Scene(s) if s.timed() => s.clock.until_due(),
            _ => None,
        }
    }
}
