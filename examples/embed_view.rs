//! A winit application that embeds fxgraph's viewer parts around its own
//! rendering (docs/library.md, "Embedding the viewer's parts"): its scene
//! texture goes through an effect each frame; a side panel shows the library's
//! parameter panel and pass inspector (`fxgraph::view::panel::params_section`
//! and `passes_section`, over a `view::model::Model::for_effect`), whose changes
//! come back as `UiEvent`s applied with `view::fx::Fx` (`Effect::set`, planned
//! again when the passes change) and `Prepared::inspect`; the library's image
//! pass (`fxgraph::view::present`) draws the output, or the inspected pass as the
//! panel says to shade it, next to the panel, with an fps readout
//! (`view::fps::FpsCounter`).
//!
//! Run: `cargo run --example embed_view [EFFECT...]` (default: glow);
//! `FX_EXAMPLE_FRAMES=N` closes the window after N frames.

use fxgraph::app::Change;
use fxgraph::gpu::context::{AdapterChoice, GpuContext};
use fxgraph::gpu::executor::{Engine, FrameInputs, Prepared};
use fxgraph::gpu::transfer::texture_2d;
use fxgraph::graph::plan::InputDesc;
use fxgraph::script::types::{ColorSpace, Format};
use fxgraph::view::fps::FpsCounter;
use fxgraph::view::fx::Fx;
use fxgraph::view::inspect::{shade_of, Target};
use fxgraph::view::model::Model;
use fxgraph::view::panel::{params_section, passes_section, UiEvent};
use fxgraph::view::present::{Placement, Presenter, Shown};
use fxgraph::view::ui_state::UiState;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

#[path = "shared/scene.rs"]
mod scene;

const SIZE: (u32, u32) = (640, 360);
const PANEL_WIDTH: f32 = 280.0;

/// The window and what draws into it.
struct Win {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    presenter: Presenter,
}

/// The application: its scene texture, the effect on it, the window.
struct App {
    engine: Engine,
    fx: Fx,
    prepared: Prepared,
    scene: wgpu::Texture,
    scene_view: wgpu::TextureView,
    output: wgpu::Texture,
    /// What is inspected and how (the pass inspector edits it).
    ui: UiState,
    fps: FpsCounter,
    frames_left: Option<u32>,
    win: Option<Win>,
}

/// The application's own rendering: a gradient with bright spots.
fn scene_texture(ctx: &GpuContext) -> wgpu::Texture {
    let (width, height) = SIZE;
    let texture = ctx.device.create_texture(&texture_2d(
        "embed_view scene",
        SIZE,
        wgpu::TextureFormat::Rgba16Float,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        &[],
    ));
    let texels = scene::gradient_with_spots(width, height);
    ctx.queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * 8),
            rows_per_image: None,
        },
        texture.size(),
    );
    texture
}

fn input_desc() -> InputDesc {
    InputDesc {
        width: SIZE.0,
        height: SIZE.1,
        format: Format::Rgba16f,
        colorspace: ColorSpace::Linear,
        aux: Vec::new(),
        aux_sizes: Vec::new(),
        viewport: None,
    }
}

impl App {
    fn new(effects: &[String]) -> Result<App, Box<dyn std::error::Error>> {
        let mut engine = Engine::new(GpuContext::new(&AdapterChoice::Auto)?);
        let mut fx = Fx::new(effects, &[], &[])?;
        let prepared =
            fx.effect_mut()?
                .prepare(&mut engine, &input_desc(), Some(Format::Rgba16f))?;
        let scene = scene_texture(&engine.ctx);
        let scene_view = scene.create_view(&wgpu::TextureViewDescriptor {
            label: Some("embed_view scene view"),
            ..Default::default()
        });
        let output = engine.ctx.device.create_texture(&texture_2d(
            "embed_view output",
            SIZE,
            wgpu::TextureFormat::Rgba16Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::STORAGE_BINDING,
            &[],
        ));
        let frames_left = std::env::var("FX_EXAMPLE_FRAMES")
            .ok()
            .and_then(|v| v.parse().ok());
        Ok(App {
            engine,
            fx,
            prepared,
            scene,
            scene_view,
            output,
            ui: UiState::default(),
            fps: FpsCounter::default(),
            frames_left,
            win: None,
        })
    }

    fn open_window(
        &mut self,
        event_loop: &ActiveEventLoop,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let attrs = Window::default_attributes()
            .with_title("fxgraph embedded")
            .with_inner_size(winit::dpi::PhysicalSize::new(960, 400));
        let window = Arc::new(event_loop.create_window(attrs)?);
        let ctx = &self.engine.ctx;
        let instance = ctx.instance.as_ref().ok_or("no wgpu instance")?;
        let surface = instance.create_surface(window.clone())?;
        let caps = surface.get_capabilities(&ctx.adapter);
        let format = *caps.formats.first().ok_or("no surface format")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&ctx.device, &config);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, format, egui_wgpu::RendererOptions::default());
        let presenter = Presenter::new(ctx, format);
        self.win = Some(Win {
            window,
            surface,
            config,
            egui_ctx,
            egui_state,
            egui_renderer,
            presenter,
        });
        Ok(())
    }

    /// The side panel: the fps readout, then the library's parameter panel and
    /// pass inspector; their changes go to `events`.
    fn panel(&mut self, ui: &mut egui::Ui, events: &mut Vec<UiEvent>) {
        let adapter = &self.engine.ctx.info.name;
        let model = Model::for_effect(&self.fx, Some(&self.prepared), adapter);
        if let Some(r) = self.fps.reading() {
            ui.label(r.text());
        }
        egui::CollapsingHeader::new("Parameters")
            .default_open(true)
            .show(ui, |ui| params_section(ui, &model, events));
        egui::CollapsingHeader::new("Passes")
            .default_open(true)
            .show(ui, |ui| passes_section(ui, &model, &mut self.ui, events));
    }

    /// Apply the panel's changes: parameters through `Fx` (`Effect::set`; planned
    /// again when the passes change), the pass inspected. The viewer's commands
    /// (its keys and buttons) are not part of this application.
    fn apply(&mut self, events: Vec<UiEvent>) {
        for e in events {
            let r = match e {
                UiEvent::Set(k, v) => self
                    .fx
                    .set(Some(&mut self.prepared), &k, &v)
                    .and_then(|c| self.applied(c)),
                UiEvent::Reset(k) => self
                    .fx
                    .reset(Some(&mut self.prepared), &k)
                    .and_then(|c| self.applied(c)),
                UiEvent::Inspect(t) => self.inspect(t),
                UiEvent::CopySet => {
                    println!("{}", self.fx.as_set_args(&self.prepared.params()));
                    Ok(())
                }
                UiEvent::Command(_) | UiEvent::AutoRange => Ok(()),
            };
            if let Err(e) = r {
                log::warn!("{e}");
            }
        }
    }

    /// A parameter change: a new effect is planned (and nothing is inspected).
    fn applied(&mut self, change: Change) -> Result<(), String> {
        if let Change::Replan(new) = change {
            let mut new = *new;
            let prepared = new
                .prepare(&mut self.engine, &input_desc(), Some(Format::Rgba16f))
                .map_err(|e| e.to_string())?;
            (self.fx.effect, self.prepared) = (Some(new), prepared);
            self.ui.inspect.target = Target::Output;
        }
        Ok(())
    }

    /// Show `target` instead of the output (a pass is kept by `Prepared::inspect`).
    fn inspect(&mut self, target: Target) -> Result<(), String> {
        let pass = match &target {
            Target::Pass(i) => Some(*i),
            _ => None,
        };
        self.prepared.inspect(pass).map_err(|e| e.to_string())?;
        self.ui.inspect.target = target;
        Ok(())
    }

    /// The texture to show and its format: the inspected pass (once written),
    /// the input, else the effect's output.
    fn shown(&self) -> (&wgpu::Texture, Format) {
        match (&self.ui.inspect.target, self.prepared.inspected()) {
            (Target::Pass(i), Some(t)) => {
                let passes = &self.prepared.plan.passes;
                (t, passes.get(*i).map_or(Format::Rgba16f, |p| p.desc.format))
            }
            (Target::Input, _) => (&self.scene, Format::Rgba16f),
            _ => (&self.output, Format::Rgba16f),
        }
    }

    /// One frame (the window is set aside while it is drawn into).
    fn frame(&mut self) -> Result<(), Box<dyn std::error::Error>> {
        let Some(mut win) = self.win.take() else {
            return Ok(());
        };
        let result = self.draw(&mut win);
        self.win = Some(win);
        result
    }

    /// The effect on the scene, the panel, the image pass.
    fn draw(&mut self, win: &mut Win) -> Result<(), Box<dyn std::error::Error>> {
        let ctx = self.engine.ctx.clone();
        let start = Instant::now();
        let raw = win.egui_state.take_egui_input(&win.window);
        let mut events = Vec::new();
        let full = win.egui_ctx.run_ui(raw, |ui| {
            events.clear();
            egui::Panel::left("embed_view panel")
                .default_size(PANEL_WIDTH)
                .resizable(false)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| self.panel(ui, &mut events))
                });
        });
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("embed_view frame"),
            });
        self.prepared.record(
            &mut self.engine,
            &mut encoder,
            &FrameInputs::single(&self.scene_view),
            &self.output,
        )?;
        win.egui_state
            .handle_platform_output(&win.window, full.platform_output);
        let mut textures_delta = full.textures_delta;
        for (id, deltas) in std::mem::take(&mut textures_delta.set) {
            for delta in &deltas {
                win.egui_renderer
                    .update_texture(&ctx.device, &ctx.queue, id, delta);
            }
        }
        // Freed after this frame is drawn (or now, when there is none).
        let free = std::mem::take(&mut textures_delta.free);
        let surface = match win.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            _ => {
                win.surface.configure(&ctx.device, &win.config);
                for id in &free {
                    win.egui_renderer.free_texture(id);
                }
                return Ok(());
            }
        };
        let target = surface.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("embed_view surface view"),
            ..Default::default()
        });
        let ppp = full.pixels_per_point;
        let (sw, sh) = (win.config.width, win.config.height);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [sw, sh],
            pixels_per_point: ppp,
        };
        let jobs = win.egui_ctx.tessellate(full.shapes, ppp);
        let extra =
            win.egui_renderer
                .update_buffers(&ctx.device, &ctx.queue, &mut encoder, &jobs, &screen);
        let (texture, format) = self.shown();
        let shown = Shown {
            texture,
            format,
            shade: Some(shade_of(&self.ui.inspect, format)),
        };
        let x = ((PANEL_WIDTH * ppp) as u32).min(sw);
        let area = [x, 0, sw - x, sh];
        let scale = ((sw - x) as f32 / SIZE.0 as f32).min(sh as f32 / SIZE.1 as f32);
        let place = Placement {
            rect: [x as f32, 0.0, SIZE.0 as f32 * scale, SIZE.1 as f32 * scale],
            area,
            split: 0.0,
            exposure: 0.0,
            range: self.ui.inspect.range,
            mark_clipping: false,
        };
        win.presenter.prepare(&ctx, shown, None, &place);
        let egui_renderer = &win.egui_renderer;
        let draw_egui =
            |rp: &mut wgpu::RenderPass<'static>| egui_renderer.render(rp, &jobs, &screen);
        win.presenter.encode(
            &mut encoder,
            &surface.texture,
            &target,
            &place,
            true,
            false,
            None,
            Some(draw_egui),
        );
        ctx.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        win.window.pre_present_notify();
        ctx.queue.present(surface);
        for id in &free {
            win.egui_renderer.free_texture(id);
        }
        win.window.request_redraw();
        self.fps.tick(Instant::now(), start.elapsed());
        self.apply(events);
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.win.is_none() {
            if let Err(e) = self.open_window(event_loop) {
                eprintln!("embed_view: {e}");
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if let Some(win) = &mut self.win {
            let _ = win.egui_state.on_window_event(&win.window, &event);
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(win) = &mut self.win {
                    win.config.width = size.width.max(1);
                    win.config.height = size.height.max(1);
                    win.surface.configure(&self.engine.ctx.device, &win.config);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame() {
                    eprintln!("embed_view: {e}");
                    event_loop.exit();
                }
                if let Some(n) = &mut self.frames_left {
                    *n = n.saturating_sub(1);
                    if *n == 0 {
                        event_loop.exit();
                    }
                }
            }
            _ => {}
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let effects: Vec<String> = std::env::args().skip(1).collect();
    let effects = if effects.is_empty() {
        vec!["glow".to_string()]
    } else {
        effects
    };
    let mut app = App::new(&effects)?;
    let event_loop = EventLoop::new()?;
    event_loop.run_app(&mut app)?;
    Ok(())
}
