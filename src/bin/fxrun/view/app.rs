//! The window: winit's event loop, the wgpu surface on the run's device (the
//! instance the adapter came from), egui's state and renderer, and the viewer's
//! state between frames.

use super::commands::key_command;
use super::reload::Reloader;
use super::script::Script;
use super::UserEvent;
use crate::{Cli, Fail};
use fxgraph::gpu::executor::Engine;
use fxgraph::view::command::Command;
use fxgraph::view::content::Content;
use fxgraph::view::fx::Fx;
use fxgraph::view::panel_cache::PanelCache;
use fxgraph::view::present::{surface_config, Presenter};
use fxgraph::view::ui_state::{UiState, PANEL_WIDTH};
use std::collections::HashSet;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoopProxy};
use winit::keyboard::Key;
use winit::window::{Window, WindowId};

/// The window and what draws into it.
pub(super) struct Win {
    pub window: Arc<Window>,
    pub surface: wgpu::Surface<'static>,
    pub config: wgpu::SurfaceConfiguration,
    pub egui_ctx: egui::Context,
    pub egui_state: egui_winit::State,
    pub egui_renderer: egui_wgpu::Renderer,
    pub presenter: Presenter,
    pub panel_cache: PanelCache,
}

/// Frame times of the run (`--timings`).
#[derive(Default)]
pub(super) struct FrameStats {
    /// Wall time of each frame: effect, panel, image pass, present (and, scripted,
    /// the wait for the GPU).
    pub frames: Vec<f64>,
    /// CPU time of recording the effect, per frame that recorded it.
    pub record: Vec<f64>,
    /// A parameter change: when it was applied, and the frame that showed it.
    pub change_at: Option<Instant>,
    pub change_shown: Vec<(f64, u64)>,
}

/// The viewer.
pub(super) struct Viewer {
    pub cli: Cli,
    pub engine: Engine,
    pub fx: Fx,
    pub content: Content,
    pub ui: UiState,
    pub script: Option<Script>,
    pub win: Option<Win>,
    pub proxy: EventLoopProxy<UserEvent>,
    pub reloader: Option<Reloader>,
    /// The effect must be recorded again (a still or a scene).
    pub dirty: bool,
    /// Reloads done (compiled, or failed to).
    pub reloads: u64,
    /// Scripted `wait-reload`: the reload count to wait for, and since when.
    pub waiting_reload: Option<(u64, Instant)>,
    /// Scripted `wait-reload`s so far.
    pub reload_waits: u64,
    pub stats: FrameStats,
    /// The error the viewer ends with.
    pub failure: Option<Fail>,
    pub last_frame: Instant,
    /// Frames shown.
    pub shown: u64,
    /// A reload was asked for (applied at the next frame).
    pub reload_pending: bool,
    /// Shift, Ctrl, ... held.
    pub modifiers: winit::keyboard::ModifiersState,
}

impl Viewer {
    pub fn new(
        cli: Cli,
        engine: Engine,
        content: Content,
        fx: Fx,
        script: Option<Script>,
        proxy: EventLoopProxy<UserEvent>,
    ) -> Result<Self, Fail> {
        let mut v = Viewer {
            cli,
            engine,
            fx,
            content,
            ui: UiState::default(),
            script,
            win: None,
            proxy,
            reloader: None,
            dirty: true,
            reloads: 0,
            waiting_reload: None,
            reload_waits: 0,
            stats: FrameStats::default(),
            failure: None,
            last_frame: Instant::now(),
            shown: 0,
            reload_pending: false,
            modifiers: Default::default(),
        };
        v.start()?;
        v.watch();
        Ok(v)
    }

    /// Load and plan what is shown first.
    fn start(&mut self) -> Result<(), Fail> {
        if let Content::Stills(s) = &mut self.content {
            s.load(&self.engine)?;
        }
        self.content.prepare(&mut self.engine, &mut self.fx)?;
        Ok(())
    }

    /// (Re)start the watcher when the files the effect reads changed.
    pub fn watch(&mut self) {
        let mut extra = HashSet::new();
        if let Content::Stills(s) = &self.content {
            if s.len() > 1 {
                if let Ok(p) = std::fs::canonicalize(s.current_path()) {
                    extra.insert(p);
                }
            }
        }
        let files = crate::watch::watched_files(&self.cli);
        let same = self
            .reloader
            .as_ref()
            .is_some_and(|r| files.iter().chain(&extra).all(|f| r.files.contains(f)));
        if same {
            return;
        }
        match Reloader::start(&self.cli, &extra, self.proxy.clone()) {
            Ok(r) => {
                eprintln!("fxrun: view: watching {} files for changes", r.files.len());
                self.reloader = Some(r);
            }
            Err(e) => eprintln!("fxrun: warning: --view: hot reload is off: {e}"),
        }
    }

    /// The result of the run, once the event loop has ended.
    pub fn finish(&mut self) -> Result<(), Fail> {
        if let Some(f) = self.failure.take() {
            return Err(f);
        }
        if self.cli.timings {
            super::frame::print_stats(&self.stats, self.shown);
        }
        Ok(())
    }

    /// Stop with an error.
    pub fn fail(&mut self, event_loop: &ActiveEventLoop, f: Fail) {
        if self.failure.is_none() {
            self.failure = Some(f);
        }
        event_loop.exit();
    }

    /// The window's first size: the image at 1:1 plus the panel, within the monitor.
    fn initial_size(&self, event_loop: &ActiveEventLoop) -> winit::dpi::PhysicalSize<u32> {
        let (w, h) = self
            .content
            .output()
            .map(|(t, _)| (t.width(), t.height()))
            .unwrap_or((1280, 720));
        let screen = event_loop
            .primary_monitor()
            .or_else(|| event_loop.available_monitors().next())
            .map(|m| m.size())
            .unwrap_or(winit::dpi::PhysicalSize::new(1920, 1080));
        let panel = if self.ui.panel { PANEL_WIDTH as u32 } else { 0 };
        winit::dpi::PhysicalSize::new(
            (w + panel).clamp(640, screen.width.max(640)),
            h.clamp(720, screen.height.max(720)),
        )
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<(), Fail> {
        let attrs = Window::default_attributes()
            .with_title(self.title())
            .with_inner_size(self.initial_size(event_loop));
        let window = Arc::new(event_loop.create_window(attrs).map_err(|e| Fail {
            code: 1,
            message: format!("--view: cannot open a window: {e}"),
        })?);
        let ctx = &self.engine.ctx;
        let gpu_fail = |m: String| Fail {
            code: 2,
            message: format!("--view: {m}"),
        };
        let instance = ctx
            .instance
            .as_ref()
            .ok_or_else(|| gpu_fail("no wgpu instance".into()))?;
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| gpu_fail(format!("cannot draw into the window: {e}")))?;
        if !ctx.adapter.is_surface_supported(&surface) {
            return Err(gpu_fail(format!(
                "the adapter {} cannot present to this window (pick another with --adapter)",
                ctx.info.name
            )));
        }
        let config = self.surface_config(&surface, window.inner_size())?;
        let format = config.format;
        let size = window.inner_size();
        ctx.scoped("viewer surface", |device| {
            surface.configure(device, &config)
        })
        .map_err(|e| gpu_fail(e.to_string()))?;
        let egui_ctx = egui::Context::default();
        let max_side = ctx.device.limits().max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_side),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, format, egui_wgpu::RendererOptions::default());
        let presenter = Presenter::new(ctx, format);
        log::info!("--view: surface {format:?}, {}x{}", size.width, size.height);
        self.win = Some(Win {
            window,
            surface,
            config,
            egui_ctx,
            egui_state,
            egui_renderer,
            presenter,
            panel_cache: PanelCache::default(),
        });
        Ok(())
    }

    /// The surface's configuration ([`surface_config`]): no vsync in scripted runs
    /// (tests, benchmarks are not held to the display's rate).
    fn surface_config(
        &self,
        surface: &wgpu::Surface<'static>,
        size: winit::dpi::PhysicalSize<u32>,
    ) -> Result<wgpu::SurfaceConfiguration, Fail> {
        let vsync = self.script.is_none();
        surface_config(&self.engine.ctx, surface, (size.width, size.height), vsync).ok_or(Fail {
            code: 2,
            message: "--view: the window offers no surface format".into(),
        })
    }

    /// The window's title: the effects, what is shown, and whether an error is.
    pub fn title(&self) -> String {
        let error = if self.ui.error.is_some() {
            " — error (see the panel)"
        } else {
            ""
        };
        format!(
            "fxrun {} — {}{error}",
            self.fx.names().join(" "),
            self.content.caption()
        )
    }

    /// Configure the surface for the window's size.
    pub fn resize_surface(&mut self, width: u32, height: u32) {
        let Some(w) = &mut self.win else { return };
        if width == 0 || height == 0 {
            return;
        }
        w.config.width = width;
        w.config.height = height;
        w.surface.configure(&self.engine.ctx.device, &w.config);
    }

    /// Does anything need frames without input (playing, flying, scripted)?
    fn animating(&self) -> bool {
        let flying = matches!(&self.content, Content::Scene(s) if s.control.keys.any());
        let playing = self.content.playing() == Some(true);
        self.script.is_some() || flying || playing || self.ui.continuous || self.reload_pending
    }
}

impl ApplicationHandler<UserEvent> for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.win.is_some() {
            return;
        }
        if let Err(f) = self.open_window(event_loop) {
            self.fail(event_loop, f);
            return;
        }
        if let Some(w) = &self.win {
            w.window.request_redraw();
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, event: UserEvent) {
        match event {
            UserEvent::FilesChanged => {
                self.reload_pending = true;
                if let Some(w) = &self.win {
                    w.window.request_redraw();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(win) = &self.win else { return };
        let typing = win.egui_ctx.egui_wants_keyboard_input();
        // Our keys first, unless a text field of the panel has the keyboard.
        if let WindowEvent::KeyboardInput { event: key, .. } = &event {
            if !typing {
                let mods = self.modifiers;
                let pressed = key.state == ElementState::Pressed;
                if self.fly_key(&key.logical_key, pressed, mods.shift_key()) {
                    return;
                }
                if let Some(c) = key_command(&key.logical_key, mods.control_key()) {
                    if pressed && (!key.repeat || c.repeats()) {
                        self.command(event_loop, c);
                    }
                    return;
                }
            }
        }
        if let WindowEvent::ModifiersChanged(m) = &event {
            self.modifiers = m.state();
        }
        let Some(win) = &mut self.win else { return };
        let response = win.egui_state.on_window_event(&win.window, &event);
        if response.repaint {
            win.window.request_redraw();
        }
        match event {
            WindowEvent::CloseRequested => self.command(event_loop, Command::Quit),
            WindowEvent::Resized(size) => {
                self.resize_surface(size.width, size.height);
                if let Some(w) = &self.win {
                    w.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(w) = &self.win else { return };
        if let Some((_, since)) = self.waiting_reload {
            // Scripted wait-reload: look again soon (the reload event wakes us).
            event_loop.set_control_flow(ControlFlow::WaitUntil(
                since.max(Instant::now()) + Duration::from_millis(200),
            ));
            w.window.request_redraw();
            return;
        }
        let until_due = self.content.until_due();
        if let (Some(wait), None) = (until_due, &self.script) {
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + wait));
            if wait.is_zero() {
                w.window.request_redraw();
            }
            return;
        }
        event_loop.set_control_flow(ControlFlow::Wait);
        if self.animating() {
            w.window.request_redraw();
        }
    }
}

impl Viewer {
    /// Fly keys of a scene (held and released); true when the key was one.
    fn fly_key(&mut self, key: &Key, pressed: bool, shift: bool) -> bool {
        let Content::Scene(s) = &mut self.content else {
            return false;
        };
        s.control.keys.fast = shift;
        let fly = matches!(key, Key::Character(c) if s.control.keys.set_letter(c, pressed));
        if fly {
            self.redraw();
        }
        fly
    }
}
