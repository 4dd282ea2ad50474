//! Everything that changes the viewer, in one place: keys (and scripted `key`
//! actions), the panel's parameter changes (and scripted `set`/`reset`),
//! inspecting, screenshots, reloads and the scripted actions.

use super::app::Viewer;
use super::screenshot;
use super::script::Action;
use crate::{stdout_result, Fail};
use fxgraph::app::Change;
use fxgraph::app::Effect;
use fxgraph::io::SaveOptions;
use fxgraph::script::types::Format;
use fxgraph::view::command::Command;
use fxgraph::view::content::Content;
use fxgraph::view::inspect::Target;
use std::io::BufRead as _;
use std::path::PathBuf;
use std::time::Instant;
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{Key, NamedKey};

/// The command of a key (docs/cli.md lists them).
pub(super) fn key_command(key: &Key, ctrl: bool) -> Option<Command> {
    Some(match key {
        Key::Named(NamedKey::ArrowRight) | Key::Named(NamedKey::PageDown) => Command::Next,
        Key::Named(NamedKey::ArrowLeft) | Key::Named(NamedKey::PageUp) => Command::Prev,
        Key::Named(NamedKey::Home) => Command::First,
        Key::Named(NamedKey::Space) => Command::PlayPause,
        Key::Named(NamedKey::Tab) => Command::TogglePanel,
        Key::Named(NamedKey::Escape) => Command::Quit,
        Key::Named(NamedKey::F12) => Command::Screenshot,
        Key::Named(NamedKey::ArrowDown) => Command::InspectNext,
        Key::Named(NamedKey::ArrowUp) => Command::InspectPrev,
        Key::Character(c) => match c.to_lowercase().as_str() {
            "q" if ctrl => Command::Quit,
            "f" => Command::Fit,
            "1" => Command::OneToOne,
            "+" | "=" => Command::ZoomIn,
            "-" => Command::ZoomOut,
            "b" => Command::ToggleSplit,
            "p" => Command::Screenshot,
            "h" => Command::CameraHome,
            _ => return None,
        },
        _ => return None,
    })
}

/// The command of a key name (`--view-do K:key NAME`).
pub(super) fn named_command(name: &str) -> Option<Command> {
    let key = match name.to_lowercase().as_str() {
        "right" => Key::Named(NamedKey::ArrowRight),
        "left" => Key::Named(NamedKey::ArrowLeft),
        "up" => Key::Named(NamedKey::ArrowUp),
        "down" => Key::Named(NamedKey::ArrowDown),
        "pagedown" => Key::Named(NamedKey::PageDown),
        "pageup" => Key::Named(NamedKey::PageUp),
        "home" => Key::Named(NamedKey::Home),
        "space" => Key::Named(NamedKey::Space),
        "tab" => Key::Named(NamedKey::Tab),
        "escape" | "esc" => Key::Named(NamedKey::Escape),
        "f12" => Key::Named(NamedKey::F12),
        other if other.chars().count() == 1 => Key::Character(other.into()),
        _ => return None,
    };
    key_command(&key, false)
}

impl Viewer {
    /// Run a command.
    pub fn command(&mut self, event_loop: &ActiveEventLoop, c: Command) {
        let result: Result<(), String> = match c {
            Command::Quit => {
                event_loop.exit();
                Ok(())
            }
            Command::Next | Command::Prev | Command::First => self.navigate(c),
            Command::PlayPause => {
                self.content.play_pause();
                Ok(())
            }
            Command::Fit => {
                self.ui.fit = true;
                Ok(())
            }
            Command::OneToOne => {
                match self.content.image_size() {
                    Some(size) => self.ui.one_to_one(size),
                    None => {
                        self.ui.fit = false;
                        self.ui.zoom = 1.0;
                    }
                }
                Ok(())
            }
            Command::ZoomIn | Command::ZoomOut => {
                let f = if c == Command::ZoomIn { 1.25 } else { 0.8 };
                self.zoom_by(f, None);
                Ok(())
            }
            Command::TogglePanel => {
                self.ui.panel = !self.ui.panel;
                Ok(())
            }
            Command::ToggleSplit => {
                self.ui.split = match self.ui.split {
                    Some(_) => None,
                    None => Some(0.5),
                };
                Ok(())
            }
            Command::Screenshot => self
                .screenshot(None)
                .map(|p| self.ui.status = format!("wrote {}", p.display())),
            Command::CameraHome => {
                if let Content::Scene(s) = &mut self.content {
                    s.home();
                    self.dirty = true;
                }
                Ok(())
            }
            Command::InspectNext | Command::InspectPrev => {
                let n = self
                    .content
                    .prepared_ref()
                    .map_or(0, |p| p.plan.passes.len());
                let next = self.ui.inspect.target.step(n, c == Command::InspectNext);
                self.inspect(next)
            }
        };
        if let Err(e) = result {
            self.ui.status = e;
        }
        self.redraw();
    }

    /// Ask for a frame.
    pub fn redraw(&self) {
        if let Some(w) = &self.win {
            w.window.request_redraw();
        }
    }

    /// Zoom by `factor` around `at` (area pixels; `None`: the area's centre).
    pub fn zoom_by(&mut self, factor: f32, at: Option<[f32; 2]>) {
        if let Some(size) = self.content.image_size() {
            self.ui.zoom_by(size, factor, at);
        }
    }

    /// Next, previous or first image or frame.
    fn navigate(&mut self, c: Command) -> Result<(), String> {
        let again = self
            .content
            .navigate(&mut self.engine, &mut self.fx, c)
            .map_err(|e| e.to_string())?;
        if again {
            self.dirty = true;
            if let Content::Stills(_) = &self.content {
                self.watch();
            }
        }
        Ok(())
    }

    /// Set a parameter: the panel's controls and `--view-do set` come here.
    pub fn set_param(&mut self, key: &str, value: &str) -> Result<(), String> {
        let change = self.fx.set(self.content.prepared(), key, value)?;
        self.applied(change)
    }

    /// Reset a parameter to the effect's value.
    pub fn reset_param(&mut self, key: &str) -> Result<(), String> {
        let change = self.fx.reset(self.content.prepared(), key)?;
        self.applied(change)
    }

    /// Show a change; a new effect that cannot be planned leaves the old one.
    fn applied(&mut self, change: Change) -> Result<(), String> {
        self.stats.change_at = Some(Instant::now());
        if let Change::Replan(effect) = change {
            self.replan_with(*effect)?;
        }
        self.rerun();
        Ok(())
    }

    /// Show the change: record a still or a scene again; a paused sequence without
    /// feedback runs its frame again (with feedback the change shows from the
    /// next frame).
    fn rerun(&mut self) {
        self.dirty = true;
        if let Err(e) = self.content.rerun_paused(&mut self.engine, &mut self.fx) {
            self.ui.status = e.to_string();
        }
    }

    /// Plan `effect` for what is shown; the old effect stays on an error.
    pub fn replan_with(&mut self, effect: Effect) -> Result<(), String> {
        let old = self.fx.effect.replace(effect);
        match self.content.prepare(&mut self.engine, &mut self.fx) {
            Ok(()) => {
                self.dirty = true;
                Ok(())
            }
            Err(e) => {
                self.fx.effect = old;
                Err(e.to_string())
            }
        }
    }

    /// Compile and plan again (a watched file changed). Errors are shown in the
    /// window and printed; the last good image stays.
    pub fn reload(&mut self) {
        self.reload_pending = false;
        self.reloads += 1;
        let result = (|| -> Result<(), String> {
            if let Content::Stills(s) = &mut self.content {
                s.load(&self.engine).map_err(|e| e.to_string())?;
            }
            if self.fx.graph().is_none() {
                return Ok(());
            }
            let effect = self.fx.compile().map_err(|e| e.to_string())?;
            self.replan_with(effect)
        })();
        match result {
            Ok(()) => {
                self.ui.error = None;
                self.ui.status = "reloaded".into();
                eprintln!("fxrun: view: reloaded");
                self.rerun();
            }
            Err(e) => {
                eprintln!(
                    "fxrun: view: reload failed; the last good image stays:\n{}",
                    e.trim_end()
                );
                self.ui.error = Some(e);
            }
        }
        if let Some(w) = &self.win {
            w.window.set_title(&self.title());
        }
        self.watch();
    }

    /// Show `target` instead of the output.
    pub fn inspect(&mut self, target: Target) -> Result<(), String> {
        let pass = match &target {
            Target::Pass(i) => Some(*i),
            _ => None,
        };
        if let Some(p) = self.content.prepared() {
            p.inspect(pass).map_err(|e| e.to_string())?;
        } else if pass.is_some() {
            return Err("no effect is planned".into());
        }
        self.ui.inspect.shade = None;
        self.ui.inspect.range = match &target {
            Target::Aux(name) => self.content.aux_range(name),
            _ => (0.0, 1.0),
        };
        self.ui.inspect.target = target;
        self.rerun();
        Ok(())
    }

    /// Inspect by name: a pass's path or last part, `output`, `input`, `aux:NAME`.
    pub fn inspect_by_name(&mut self, name: &str) -> Result<(), String> {
        let target = Target::by_name(self.content.prepared_ref(), name)?;
        self.inspect(target)
    }

    /// The texture shown (at full resolution) and its format.
    pub fn shown_texture(&mut self) -> Option<(wgpu::Texture, Format)> {
        self.content.shown(&self.engine, &self.ui.inspect.target)
    }

    /// Write what is shown to `path` (else `--screenshot`, `-o FILE`, or a new
    /// `fxrun-view-NNNN` file); returns the path written.
    pub fn screenshot(&mut self, path: Option<PathBuf>) -> Result<PathBuf, String> {
        let (tex, format) = self.shown_texture().ok_or("nothing is shown yet")?;
        let out_file = self
            .cli
            .output
            .clone()
            .filter(|o| fxgraph::io::FileFormat::from_path(o).is_some());
        let path = path
            .or(self.cli.screenshot.clone())
            .or(out_file)
            .unwrap_or_else(|| screenshot::next_free_name(format));
        let opts = SaveOptions {
            bit_depth: self.cli.bit_depth,
            assume_linear: self.cli.assume_linear,
        };
        screenshot::save(&self.engine.ctx, &tex, format, &path, &opts)
            .map_err(|e| e.to_string())?;
        eprintln!("fxrun: view: wrote {}", path.display());
        Ok(path)
    }

    /// "Copy as --set": the values set, as arguments; printed and put on the clipboard.
    pub fn copy_set(&mut self) -> String {
        let params = self
            .content
            .prepared_ref()
            .map(|p| p.params())
            .unwrap_or_default();
        let text = self.fx.as_set_args(&params);
        outln!("{text}");
        if let Some(w) = &self.win {
            w.egui_ctx.copy_text(text.clone());
        }
        self.ui.copied = Some(text.clone());
        text
    }

    /// Run scripted actions (after a frame was shown).
    pub fn run_actions(&mut self, event_loop: &ActiveEventLoop, actions: Vec<Action>) {
        for a in actions {
            let r = match &a {
                Action::Set(k, v) => self.set_param(k, v),
                Action::Reset(k) => self.reset_param(k),
                Action::Inspect(n) => self.inspect_by_name(n),
                Action::Key(k) => match named_command(k) {
                    Some(c) => {
                        self.command(event_loop, c);
                        Ok(())
                    }
                    None => Err(format!("key {k}: no command on that key")),
                },
                Action::CopySet => {
                    self.copy_set();
                    Ok(())
                }
                Action::WaitReload => {
                    // The n-th wait is for the n-th reload (one may already be done).
                    self.reload_waits += 1;
                    self.waiting_reload = Some((self.reload_waits, Instant::now()));
                    Ok(())
                }
                Action::Pause => {
                    self.pause();
                    Ok(())
                }
            };
            if let Err(e) = r {
                self.fail(
                    event_loop,
                    Fail {
                        code: 1,
                        message: format!("--view-do {a}: {e}"),
                    },
                );
                return;
            }
        }
    }

    /// Print where the window's image is on the screen and wait for a line on stdin.
    fn pause(&mut self) {
        let (wx, wy) = self
            .win
            .as_ref()
            .and_then(|w| w.window.inner_position().ok())
            .map_or((0, 0), |p| (p.x, p.y));
        let [x, y, w, h] = self.ui.area;
        let img = self.placement_rect();
        eprintln!(
            "fxrun: view: paused at frame {}: window at {wx},{wy}; image area {x},{y} {w}x{h}; image at {},{} {}x{} (press Enter to go on)",
            self.shown,
            wx + img[0].round() as i32,
            wy + img[1].round() as i32,
            img[2].round() as u32,
            img[3].round() as u32,
        );
        let mut line = String::new();
        let _ = std::io::stdin().lock().read_line(&mut line);
    }
}
