//! One frame of the viewer: a pending reload, the camera, the next sequence frame,
//! planning, the effect recorded into the frame's encoder, the panel (egui), the
//! image pass and egui drawn into the surface texture, one submission, present;
//! then the panel's changes are applied (the next frame shows them) and, when
//! scripted, the actions of this frame run.

use super::app::{FrameStats, Viewer};
use crate::Fail;
use fxgraph::gpu::fullscreen::begin_color_pass;
use fxgraph::view::content::Content;
use fxgraph::view::inspect::{pass_rows, shade_of};
use fxgraph::view::panel::{self, ImageInput, Model, UiEvent};
use fxgraph::view::panel_cache::PanelPaint;
use fxgraph::view::present::{Placement, Shown};
use fxgraph::view::ui_state::Figures;
use std::time::{Duration, Instant};
use winit::event_loop::ActiveEventLoop;

/// How often the panel's figures (frame and pass times) are refreshed.
const FIGURES_EVERY: Duration = Duration::from_millis(500);

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
        if let Some((n, since)) = self.waiting_reload {
            if self.reloads < n {
                if since.elapsed() > RELOAD_WAIT {
                    let f = Fail {
                        code: 2,
                        message: "--view-do wait-reload: no watched file changed in 10 minutes"
                            .into(),
                    };
                    self.fail(event_loop, f);
                }
                return;
            }
            self.waiting_reload = None;
        }
        let scripted = self.script.is_some();
        if let Content::Scene(s) = &mut self.content {
            let mut cam = s.camera;
            if s.control.fly(&mut cam, dt) {
                s.camera = cam;
                s.camera_moved();
                self.dirty = true;
            }
        }
        if let Content::Scene(s) = &mut self.content {
            // A scene's clock: as a sequence's frames.
            let c = &s.clock;
            if s.timed() && ((scripted && self.shown > 0 && c.playing) || (!scripted && c.due())) {
                let next = c.frame + 1;
                s.set_frame(next);
                self.dirty = true;
            }
        }
        if let Content::Playback(p) = &mut self.content {
            // Scripted: one frame further per frame shown while playing (the first
            // shows frame 0).
            if (scripted && self.shown > 0 && p.playing) || (!scripted && p.due()) {
                if let Err(e) = p.advance(&mut self.engine) {
                    self.ui.status = e.to_string();
                }
            }
        }
        if self.content.needs_plan() {
            if let Err(e) = self.content.prepare(&mut self.engine, &mut self.fx) {
                self.ui.error = Some(e.to_string());
            }
            self.dirty = true;
        }
        let device = self.engine.ctx.device.clone();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("viewer frame"),
        });
        let record = self.content.rerecordable() && (self.dirty || self.ui.continuous || scripted);
        if record {
            let t = Instant::now();
            match self.content.record(&mut self.engine, &mut encoder) {
                Ok(()) => {
                    self.dirty = false;
                    self.stats.record.push(ms(t.elapsed()));
                }
                Err(e) => self.ui.error = Some(e.to_string()),
            }
        }
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
        self.shown += 1;
        self.stats.frames.push(ms(t0.elapsed()));
        self.ui.fps.tick(Instant::now(), t0.elapsed());
        if let Some(at) = self.stats.change_at.take() {
            self.stats.change_shown.push((ms(at.elapsed()), self.shown));
        }
        self.apply_input(&input);
        for e in events {
            self.apply_event(event_loop, e);
        }
        if let Some(w) = &self.win {
            w.window.set_title(&self.title());
        }
        self.script_step(event_loop);
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
        let before = if self.ui.split.is_some() {
            self.content
                .before(&self.engine)
                .map(|(t, f)| (t.clone(), f))
        } else {
            None
        };
        let shown = self.shown_texture();
        let ctx = self.engine.ctx.clone();
        let Some(win) = &mut self.win else {
            return Ok((Vec::new(), ImageInput::default()));
        };
        let raw = win.egui_state.take_egui_input(&win.window);
        let mut events = Vec::new();
        let mut input = ImageInput::default();
        let ui_state = &mut self.ui;
        let full = win.egui_ctx.run_ui(raw, |ui| {
            events.clear();
            input = panel::show(ui, &model, ui_state, &mut events);
        });
        win.egui_state
            .handle_platform_output(&win.window, full.platform_output);
        let ppp = full.pixels_per_point;
        let (sw, sh) = (win.config.width, win.config.height);
        let a = input.area;
        let area = [
            (a[0] * ppp).round().clamp(0.0, sw as f32) as u32,
            (a[1] * ppp).round().clamp(0.0, sh as f32) as u32,
            (a[2] * ppp).round().clamp(0.0, sw as f32) as u32,
            (a[3] * ppp).round().clamp(0.0, sh as f32) as u32,
        ];
        let area = [
            area[0],
            area[1],
            area[2].min(sw - area[0]),
            area[3].min(sh - area[1]),
        ];
        self.ui.area = area;
        // egui's textures are updated even when no frame is drawn.
        for (id, deltas) in &full.textures_delta.set {
            for delta in deltas {
                win.egui_renderer
                    .update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        let textures_changed = !full.textures_delta.set.is_empty();
        let mut textures_delta = full.textures_delta;
        textures_delta.set.clear();
        let surface = match win.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                log::debug!("--view: the surface is outdated: configured again");
                win.surface.configure(&ctx.device, &win.config);
                win.window.request_redraw();
                Self::free_textures(win, textures_delta);
                return Ok((events, input));
            }
            other => {
                log::debug!("--view: no surface texture this frame ({other:?})");
                win.window.request_redraw();
                Self::free_textures(win, textures_delta);
                return Ok((events, input));
            }
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
        let rect = self.ui.image_rect(model.image_size);
        let place = Placement {
            rect,
            area,
            split: self.ui.split.unwrap_or(0.0),
            exposure: self.ui.exposure,
            range: self.ui.inspect.range,
            mark_clipping: self.ui.mark_clipping,
        };
        if let Some((tex, format)) = &shown {
            let after = Shown {
                texture: tex,
                format: *format,
                shade: Some(shade_of(&self.ui.inspect, *format)),
            };
            let before = before.as_ref().map(|(t, f)| Shown {
                texture: t,
                format: *f,
                shade: None,
            });
            win.presenter.prepare(&ctx, after, before, &place);
        }
        let split = before.is_some() && place.split > 0.0;
        let panel_x = self.ui.panel.then_some(area[0] + area[2]);
        let paint = win
            .panel_cache
            .plan(&jobs, ppp, (sw, sh), panel_x, textures_changed);
        let egui_renderer = &win.egui_renderer;
        let draw_egui =
            |rp: &mut wgpu::RenderPass<'static>| egui_renderer.render(rp, &jobs, &screen);
        let (panel, direct) = match paint {
            PanelPaint::Nothing => (None, false),
            PanelPaint::Direct => (None, true),
            PanelPaint::Cached { rect, redraw } => {
                let cache = win
                    .panel_cache
                    .texture(&ctx.device, (sw, sh), win.config.format);
                if redraw {
                    let view = cache.create_view(&wgpu::TextureViewDescriptor {
                        label: Some("viewer panel cache view"),
                        ..Default::default()
                    });
                    let clear = wgpu::LoadOp::Clear(wgpu::Color::BLACK);
                    let mut rp = begin_color_pass(&mut encoder, "viewer panel", &view, clear, None)
                        .forget_lifetime();
                    draw_egui(&mut rp);
                }
                (Some((cache, rect)), false)
            }
        };
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
        ctx.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        win.window.pre_present_notify();
        ctx.queue.present(surface);
        Self::free_textures(win, textures_delta);
        Ok((events, input))
    }

    /// Free the egui textures a frame no longer uses.
    fn free_textures(win: &mut super::app::Win, delta: egui::TexturesDelta) {
        for id in &delta.free {
            win.egui_renderer.free_texture(id);
        }
    }

    /// What the panel shows (its own copy: the panel runs while the window is borrowed).
    fn model(&mut self) -> Model {
        let prepared = self.content.prepared_ref();
        let params = prepared.map(|p| p.params()).unwrap_or_default();
        let defaults = params.iter().map(|p| self.fx.pass_default(p)).collect();
        let set = params
            .iter()
            .map(|p| self.fx.pass_is_set(&p.name))
            .collect();
        let mut rows = prepared.map(pass_rows).unwrap_or_default();
        let timed = prepared.is_some_and(|p| !p.gpu_timings().is_empty());
        // The figures change every frame: shown twice a second (readable, and the
        // panel is not drawn again for them every frame: panel_cache.rs).
        let stale = self
            .ui
            .figures
            .as_ref()
            .is_none_or(|f| f.at.elapsed() >= FIGURES_EVERY || f.gpu_ms.len() != rows.len());
        if stale {
            self.ui.figures = Some(Figures {
                at: Instant::now(),
                frame_ms: self.stats.frames.last().copied(),
                gpu_ms: rows.iter().map(|r| r.gpu_ms).collect(),
                fps: self.ui.fps.reading(),
            });
        }
        let figures = self.ui.figures.as_ref().expect("set above");
        for (r, ms) in rows.iter_mut().zip(&figures.gpu_ms) {
            r.gpu_ms = *ms;
        }
        let (frame_ms, fps) = (figures.frame_ms, figures.fps);
        let image_size = self
            .content
            .output()
            .map(|(t, _)| (t.width() as f32, t.height() as f32))
            .unwrap_or((1.0, 1.0));
        Model {
            caption: self.content.caption(),
            adapter: self.engine.ctx.info.name.clone(),
            effect_params: self.fx.effect_params().to_vec(),
            params,
            defaults,
            set,
            rows,
            timed,
            aux: self
                .content
                .aux()
                .into_iter()
                .map(|(n, _, f)| (n, f))
                .collect(),
            output_format: self.content.output_format(),
            shown_format: self.shown_texture().map(|(_, f)| f),
            playing: match &self.content {
                Content::Playback(p) => Some(p.playing),
                Content::Scene(s) if s.timed() => Some(s.clock.playing),
                _ => None,
            },
            scene: matches!(self.content, Content::Scene(_)),
            frame_ms,
            fps,
            image_size,
            set_args: self.ui.copied.clone(),
        }
    }

    /// Mouse input over the image: pan and zoom it, or move a scene's camera.
    fn apply_input(&mut self, input: &ImageInput) {
        let [_, _, aw, ah] = self.ui.area;
        if let Content::Scene(s) = &mut self.content {
            let mut again = false;
            if s.resize(aw, ah) {
                self.dirty = true;
                again = true;
            }
            let mut cam = s.camera;
            let mut moved = false;
            if input.drag != [0.0, 0.0] {
                if input.primary {
                    s.control.orbit(&mut cam, input.drag[0], input.drag[1]);
                } else {
                    s.control
                        .pan(&mut cam, input.drag[0], input.drag[1], ah as f32);
                }
                moved = true;
            }
            if input.scroll != 0.0 {
                s.control.dolly(&mut cam, input.scroll);
                moved = true;
            }
            if moved {
                s.camera = cam;
                s.camera_moved();
                self.dirty = true;
                again = true;
            }
            if again {
                self.redraw();
            }
            return;
        }
        if input.drag != [0.0, 0.0] {
            if self.ui.fit {
                self.zoom_by(1.0, None);
            }
            self.ui.center[0] -= input.drag[0] / self.ui.zoom;
            self.ui.center[1] -= input.drag[1] / self.ui.zoom;
            self.redraw();
        }
        if input.scroll != 0.0 {
            self.zoom_by(1.25f32.powf(input.scroll), input.hover);
            self.redraw();
        }
        if input.double_click {
            self.ui.fit = !self.ui.fit;
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
