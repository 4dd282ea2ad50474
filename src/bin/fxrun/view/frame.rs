//! One frame of the viewer: a pending reload, the camera, the next sequence frame,
//! planning, the effect recorded into the frame's encoder, the panel (egui), the
//! image pass and egui drawn into the surface texture, one submission, present;
//! then the panel's changes are applied (the next frame shows them) and, when
//! scripted, the actions of this frame run.

use super::app::{FrameStats, Viewer, Win};
use crate::Fail;
use fxgraph::gpu::context::GpuContext;
use fxgraph::script::types::Format;
use fxgraph::view::content::Content;
use fxgraph::view::frame_paint as paint;
use fxgraph::view::panel::{self, Model, UiEvent};
use fxgraph::view::ui_state::{ImageInput, UiState};
use std::time::{Duration, Instant};
use winit::event_loop::ActiveEventLoop;

/// How long a scripted `wait-reload` waits.
const RELOAD_WAIT: Duration = Duration::from_secs(600);

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// `--timings`: the frame times of the run.
pub(super) fn print_stats(stats: &FrameStats, shown: u64) {
    // The first frames build pipelines and textures: the steady state is after them.
    let skip = stats.frames.len().min(2);
    eprintln!(
        "fxrun: view: {shown} frames; median frame {:.2} ms (after the first {skip}); median effect recording {:.2} ms (CPU)",
        median(&stats.frames[skip..]),
        median(&stats.record[stats.record.len().min(skip)..]),
    );
    for (latency, frame) in &stats.change_shown {
        eprintln!(
            "fxrun: view: parameter change shown in frame {frame}, {latency:.2} ms after it was made"
        );
    }
}

impl Viewer {
    /// The image's rectangle in surface pixels (x, y, width, height) for this frame.
    pub fn placement_rect(&self) -> [f32; 4] {
        let size = self
            .content
            .output()
            .map(|(t, _)| (t.width() as f32, t.height() as f32))
            .unwrap_or((1.0, 1.0));
        self.ui.image_rect(size)
    }

    /// Draw one frame (see the module's documentation).
    pub fn frame(&mut self, event_loop: &ActiveEventLoop) {
        let t0 = Instant::now();
        let dt = (t0 - self.last_frame).as_secs_f32();
        self.last_frame = t0;
        if self.reload_pending {
            self.reload();
        }
        if self.still_waiting_reload(event_loop) {
            return;
        }
        let scripted = self.script.is_some();
        match self
            .content
            .advance(&mut self.engine, dt, scripted, self.shown == 0)
        {
            Ok(again) => self.dirty |= again,
            Err(e) => self.ui.status = e.to_string(),
        }
        self.plan_if_needed();
        let device = self.engine.ctx.device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("viewer frame"),
        });
        self.record_effect(&mut encoder, scripted);
        let (events, input) = match self.draw(encoder) {
            Ok(x) => x,
            Err(f) => {
                self.fail(event_loop, f);
                return;
            }
        };
        if scripted {
            // The frame is on screen once the GPU is done with it.
            let _ = device.poll(wgpu::PollType::wait_indefinitely());
        }
        self.count_frame(t0);
        self.apply_input(&input);
        for e in events {
            self.apply_event(event_loop, e);
        }
        if let Some(w) = &self.win {
            w.window.set_title(&self.title());
        }
        self.script_step(event_loop);
    }

    /// Scripted `wait-reload`: true while the reload waited for has not come
    /// (no frame is drawn); fails after [`RELOAD_WAIT`].
    fn still_waiting_reload(&mut self, event_loop: &ActiveEventLoop) -> bool {
        let Some((n, since)) = self.waiting_reload else {
            return false;
        };
        if self.reloads >= n {
            self.waiting_reload = None;
            return false;
        }
        if since.elapsed() > RELOAD_WAIT {
            let f = Fail {
                code: 2,
                message: "--view-do wait-reload: no watched file changed in 10 minutes".into(),
            };
            self.fail(event_loop, f);
        }
        true
    }

    /// Plan the effect again when what is shown needs it (a new size or format).
    fn plan_if_needed(&mut self) {
        if self.content.needs_plan() {
            if let Err(e) = self.content.prepare(&mut self.engine, &mut self.fx) {
                self.ui.error = Some(e.to_string());
            }
            self.dirty = true;
        }
    }

    /// Record the effect of a still or a scene into `encoder` when it changed
    /// (every frame when continuous or scripted).
    fn record_effect(&mut self, encoder: &mut wgpu::CommandEncoder, scripted: bool) {
        let record = self.content.rerecordable() && (self.dirty || self.ui.continuous || scripted);
        if !record {
            return;
        }
        let t = Instant::now();
        match self.content.record(&mut self.engine, encoder) {
            Ok(()) => {
                self.dirty = false;
                self.stats.record.push(ms(t.elapsed()));
            }
            Err(e) => self.ui.error = Some(e.to_string()),
        }
    }

    /// A frame begun at `t0` was shown: the frame times, the fps readout, the
    /// latency of a parameter change.
    fn count_frame(&mut self, t0: Instant) {
        self.shown += 1;
        self.stats.frames.push(ms(t0.elapsed()));
        self.ui.fps.tick(Instant::now(), t0.elapsed());
        if let Some(at) = self.stats.change_at.take() {
            self.stats.change_shown.push((ms(at.elapsed()), self.shown));
        }
    }

    /// Scripted mode: this frame's actions, and the end.
    fn script_step(&mut self, event_loop: &ActiveEventLoop) {
        let Some(script) = &mut self.script else {
            return;
        };
        script.shown = self.shown;
        let due = script.due();
        let done = script.done();
        self.run_actions(event_loop, due);
        if done && self.waiting_reload.is_none() && self.failure.is_none() {
            if let Some(path) = self.cli.screenshot.clone() {
                if let Err(e) = self.screenshot(Some(path)) {
                    self.fail(
                        event_loop,
                        Fail {
                            code: 2,
                            message: e,
                        },
                    );
                    return;
                }
            }
            event_loop.exit();
        }
    }

    /// The panel, then the image pass and egui into the surface; submit, present.
    fn draw(
        &mut self,
        mut encoder: wgpu::CommandEncoder,
    ) -> Result<(Vec<UiEvent>, ImageInput), Fail> {
        let model = self.model();
        let before = self.split_before();
        let shown = self.shown_texture();
        let ctx = self.engine.ctx.clone();
        let Some(win) = &mut self.win else {
            return Ok((Vec::new(), ImageInput::default()));
        };
        let (full, events, input) = run_panel(win, &model, &mut self.ui);
        let ppp = full.pixels_per_point;
        let (sw, sh) = (win.config.width, win.config.height);
        let area = paint::area_pixels(input.area, ppp, (sw, sh));
        self.ui.area = area;
        let (textures_changed, textures_delta) =
            paint::update_textures(&mut win.egui_renderer, &ctx, full.textures_delta);
        let Some(surface) = surface_texture(win, &ctx) else {
            paint::free_textures(&mut win.egui_renderer, textures_delta);
            return Ok((events, input));
        };
        let target = surface.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("viewer surface view"),
            ..Default::default()
        });
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [sw, sh],
            pixels_per_point: ppp,
        };
        let jobs = win.egui_ctx.tessellate(full.shapes, ppp);
        let extra =
            win.egui_renderer
                .update_buffers(&ctx.device, &ctx.queue, &mut encoder, &jobs, &screen);
        let place = paint::placement(&self.ui, model.image_size, area);
        let image = shown.as_ref().map(|(t, f)| (t, *f));
        let before = before.as_ref().map(|(t, f)| (t, *f));
        paint::prepare_image(&mut win.presenter, &ctx, &self.ui, image, before, &place);
        let split = before.is_some() && place.split > 0.0;
        let panel_jobs = paint::PanelJobs {
            jobs: &jobs,
            ppp,
            size: (sw, sh),
            format: win.config.format,
            panel_x: self.ui.panel.then_some(area[0] + area[2]),
            textures_changed,
        };
        let egui_renderer = &win.egui_renderer;
        let draw_egui =
            |rp: &mut wgpu::RenderPass<'static>| egui_renderer.render(rp, &jobs, &screen);
        let (panel, direct) = paint::paint_panel(
            &mut win.panel_cache,
            &ctx,
            &mut encoder,
            &panel_jobs,
            draw_egui,
        );
        win.presenter.encode(
            &mut encoder,
            &surface.texture,
            &target,
            &place,
            shown.is_some(),
            split,
            panel,
            direct.then_some(draw_egui),
        );
        submit_and_present(win, &ctx, extra, encoder, surface);
        paint::free_textures(&mut win.egui_renderer, textures_delta);
        Ok((events, input))
    }

    /// The "before" image of the split view, when it is shown.
    fn split_before(&mut self) -> Option<(wgpu::Texture, Format)> {
        self.ui.split?;
        let (t, f) = self.content.before(&self.engine)?;
        Some((t.clone(), f))
    }

    /// What the panel shows (its own copy: the panel runs while the window is borrowed).
    fn model(&mut self) -> Model {
        let last = self.stats.frames.last().copied();
        Model::new(
            &mut self.content,
            &self.fx,
            &mut self.ui,
            &self.engine,
            last,
        )
    }

    /// Mouse input over the image: pan and zoom it, or move a scene's camera.
    fn apply_input(&mut self, input: &ImageInput) {
        let [_, _, aw, ah] = self.ui.area;
        let changed = match &mut self.content {
            Content::Scene(s) => {
                let again = s.apply_input(input, (aw, ah));
                self.dirty |= again;
                again
            }
            _ => {
                let size = self.content.image_size();
                self.ui.apply_image_input(input, size)
            }
        };
        if changed {
            self.redraw();
        }
    }

    /// A change made in the panel.
    fn apply_event(&mut self, event_loop: &ActiveEventLoop, e: UiEvent) {
        let r = match e {
            UiEvent::Set(k, v) => self.set_param(&k, &v),
            UiEvent::Reset(k) => self.reset_param(&k),
            UiEvent::Command(c) => {
                self.command(event_loop, c);
                Ok(())
            }
            UiEvent::Inspect(t) => self.inspect(t),
            UiEvent::CopySet => {
                self.copy_set();
                Ok(())
            }
            UiEvent::AutoRange => {
                let ctx = self.engine.ctx.clone();
                match self.shown_texture() {
                    Some((t, f)) => {
                        if let Some(r) = fxgraph::view::inspect::value_range(&ctx, &t, f) {
                            self.ui.inspect.range = r;
                        }
                        Ok(())
                    }
                    None => Ok(()),
                }
            }
        };
        if let Err(m) = r {
            self.ui.status = m;
        }
        self.redraw();
    }
}

/// Run the panel (egui) for this frame: its output, the changes asked for and
/// the mouse over the image area.
fn run_panel(
    win: &mut Win,
    model: &Model,
    ui_state: &mut UiState,
) -> (egui::FullOutput, Vec<UiEvent>, ImageInput) {
    let raw = win.egui_state.take_egui_input(&win.window);
    let mut events = Vec::new();
    let mut input = ImageInput::default();
    let mut full = win.egui_ctx.run_ui(raw, |ui| {
        events.clear();
        input = panel::show(ui, model, ui_state, &mut events);
    });
    let platform = std::mem::take(&mut full.platform_output);
    win.egui_state.handle_platform_output(&win.window, platform);
    (full, events, input)
}

/// The surface's texture for this frame; `None` (and another frame asked for)
/// when the surface was outdated (configured again) or gave none.
fn surface_texture(win: &mut Win, ctx: &GpuContext) -> Option<wgpu::SurfaceTexture> {
    match win.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
            return Some(t)
        }
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            log::debug!("--view: the surface is outdated: configured again");
            win.surface.configure(&ctx.device, &win.config);
        }
        other => log::debug!("--view: no surface texture this frame ({other:?})"),
    }
    win.window.request_redraw();
    None
}

/// Submit the frame's work (egui's buffers, then the frame) and present it.
fn submit_and_present(
    win: &Win,
    ctx: &GpuContext,
    extra: Vec<wgpu::CommandBuffer>,
    encoder: wgpu::CommandEncoder,
    surface: wgpu::SurfaceTexture,
) {
    ctx.queue
        .submit(extra.into_iter().chain([encoder.finish()]));
    win.window.pre_present_notify();
    ctx.queue.present(surface);
}
