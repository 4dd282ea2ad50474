//! `fxrun ... --view`: the effect's output in a window, live.
//!
//! The same effects, inputs and scene options as a normal run; instead of writing
//! files, a window (winit) shows the output on a wgpu surface of the run's device,
//! with an egui control panel. Built on the library's public API: `Effect`,
//! `Prepared::record` (into the window's frame encoder), `set_param`, `params()`,
//! `Prepared::inspect` and `Prepared::set_gpu_timings`, `gpu::stream::Stream`.
//!
//! - `app.rs`: the window, its surface and the event loop; `frame.rs`: one frame
//!   (the effect, the panel, the image pass, present); `commands.rs`: keys,
//!   panel changes, reloads and scripted actions, applied in one place.
//! - `screenshot.rs`: writing what is shown; `reload.rs`: hot reload;
//!   `script.rs`: `--view-frames` and `--view-do`; this file: the command line
//!   turned into the library's content (`fxgraph::view::content`: stills, a
//!   sequence, a scene through `fxgraph::app::SceneFrames`) and effect
//!   (`fxgraph::view::fx`).
//! - The rest is the library's `fxgraph::view`: the panel (`panel`, `model`,
//!   `ui_state`), the pass list and what is inspected (`inspect`), the image pass
//!   (`present`), the frame's painting steps (`frame_paint`), the fps readout
//!   (`fps`), camera control.
//!
//! Without a display the option fails with a clear message (exit 1).

mod app;
mod commands;
mod frame;
mod reload;
mod screenshot;
mod script;

use super::*;
use fxgraph::io::sequence::SequenceSpec;
use fxgraph::view::content::Content;
use fxgraph::view::{fx, playback, scene_view, stills};

/// Events sent to the window's event loop from other threads.
#[derive(Debug, Clone, Copy)]
pub(super) enum UserEvent {
    /// A watched file changed: compile and plan again.
    FilesChanged,
}

/// Why `--view` cannot be used with these options, if so.
fn refusal(cli: &Cli) -> Option<&'static str> {
    if cli.check || cli.plan || cli.dot.is_some() || cli.describe || cli.list || cli.adapters {
        return Some("--view shows a run; it does not take --check, --plan, --dot, --describe, --list or --adapters");
    }
    if cli.gbuffer.is_some() || cli.describe_materials {
        return Some("--view does not take --gbuffer or --describe-materials (the pass list shows the G-buffer)");
    }
    if cli.skip_existing || cli.keep_going || cli.frames.is_some() || cli.warmup > 0 {
        return Some("--view does not take --skip-existing, --keep-going, --frames or --warmup");
    }
    if cli.timings_json.is_some() {
        return Some("--view does not take --timings-json (--timings prints the frame times)");
    }
    None
}

/// Is there a display to open a window on?
fn display_named() -> Option<String> {
    let set = |v: &str| std::env::var(v).ok().filter(|s| !s.is_empty());
    set("WAYLAND_DISPLAY")
        .map(|d| format!("WAYLAND_DISPLAY={d}"))
        .or_else(|| set("WAYLAND_SOCKET").map(|d| format!("WAYLAND_SOCKET={d}")))
        .or_else(|| set("DISPLAY").map(|d| format!("DISPLAY={d}")))
}

/// The output format a file would get: `--screenshot FILE`, else `-o FILE`, else
/// `None` (the input's type decides).
fn output_format(cli: &Cli) -> Result<Option<fxgraph::script::types::Format>, Fail> {
    let file = cli.screenshot.clone().or_else(|| {
        cli.output
            .clone()
            .filter(|o| fxgraph::io::FileFormat::from_path(o).is_some())
    });
    match file {
        Some(f) => Ok(Some(
            output_format_for(&f, cli.bit_depth, cli.assume_linear).map_err(RunError::from)?,
        )),
        None => Ok(None),
    }
}

/// A scene as viewer content (`--scene`, or nothing given: the default
/// scene), with its effect (the default chain when no effect is given).
fn scene_content(
    cli: &Cli,
    engine: &Engine,
    out: Option<fxgraph::script::types::Format>,
) -> Result<(Content, fx::Fx), Fail> {
    if !cli.input.is_empty() {
        return Err(rejected("--scene renders the input: give no -i"));
    }
    // As a normal run: no effect given means the default chain.
    let mut job = scene::scene_job(cli, cli.effects.is_empty())?;
    let fixed = cli.size.is_some();
    let format = out.unwrap_or(fxgraph::script::types::Format::Rgba8Srgb);
    job.output = None;
    let fps = cli.fps.unwrap_or(30.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(rejected(format!(
            "--fps {fps}: expected a number above 0, at most 1000"
        )));
    }
    let time = cli.time.unwrap_or(0.0);
    if !(time.is_finite() && time >= 0.0) {
        return Err(rejected(format!(
            "--time {time}: must be 0 or more seconds"
        )));
    }
    let view = scene_view::SceneView::new(job, engine, fixed, format, (fps, time))?;
    let job = view.job();
    let fx = fx::Fx::new(&job.effects, &view.base, &cli.set)?;
    Ok((Content::Scene(Box::new(view)), fx))
}

/// The inputs as a sequence to play (a stream, a pattern, or a folder for a
/// temporal effect), or `None` for stills; a stream's header may set `fps`.
fn sequence_input(
    cli: &Cli,
    specs: &[SequenceSpec],
    temporal: bool,
    fps: &mut f64,
) -> Result<Option<playback::SeqInput>, Fail> {
    let seq = match specs {
        [SequenceSpec::Stdin] => Some(playback::SeqInput::Stdin),
        [SequenceSpec::Y4m(p) | SequenceSpec::Video(p)] => {
            let input = match &specs[0] {
                SequenceSpec::Y4m(_) => fxgraph::app::StreamInput::Y4mFile(p.clone()),
                _ => fxgraph::app::StreamInput::Video(p.clone()),
            };
            // The frame rate from the file's header (a video: ffmpeg's).
            let opened = fxgraph::app::OpenedInput::open(&input)?;
            let (n, d) = opened.header.fps;
            if cli.fps.is_none() && d > 0 && n > 0 {
                *fps = n as f64 / d as f64;
            }
            Some(playback::SeqInput::Stream(input))
        }
        [s @ SequenceSpec::Pattern { .. }] => Some(playback::SeqInput::Files(
            fxgraph::io::sequence::InputSequence::open(s)
                .map_err(RunError::from)?
                .frames,
        )),
        [SequenceSpec::Dir(_) | SequenceSpec::Glob(_)] if temporal => {
            Some(playback::SeqInput::Files(collect_inputs(cli, specs)?))
        }
        _ if temporal => return Err(rejected(
            "this effect reads other frames: give its frames as one -i pattern, folder or stream",
        )),
        _ => None,
    };
    Ok(seq)
}

/// What `-i` (or `--scene`) names, as viewer content, with the effect.
fn content_for(cli: &Cli, engine: &Engine) -> Result<(Content, fx::Fx), Fail> {
    let out = output_format(cli)?;
    let load = fxgraph::io::LoadOptions {
        assume_linear: cli.assume_linear,
    };
    if cli.scene.is_some() || (cli.input.is_empty() && cli.effects.is_empty()) {
        return scene_content(cli, engine, out);
    }
    if cli.effects.is_empty() {
        return Err(rejected(
            "no effect given (try `fxrun --list`, or `fxrun --help`); effects go before -i",
        ));
    }
    if cli.input.is_empty() {
        return Err(rejected("--view needs -i INPUT or --scene SCENE"));
    }
    let fx = fx::Fx::new(&cli.effects, &[], &cli.set)?;
    let temporal = fx
        .graph()
        .is_some_and(|g| g.history > 0 || g.latency > 0 || g.has_feedback());
    let specs: Vec<SequenceSpec> = cli
        .input
        .iter()
        .map(|i| SequenceSpec::parse_input(&i.to_string_lossy()))
        .collect();
    let mut fps = cli.fps.unwrap_or(25.0);
    if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
        return Err(rejected(format!(
            "--fps {fps}: expected a number above 0, at most 1000"
        )));
    }
    if cli.rate == 0 || cli.rate > 4 {
        return Err(rejected(format!("--rate {}: expected 1 to 4", cli.rate)));
    }
    let seq = sequence_input(cli, &specs, temporal, &mut fps)?;
    if let Some(input) = seq {
        if !cli.aux.is_empty() {
            return Err(rejected("--view takes --aux with a single image only"));
        }
        if let playback::SeqInput::Files(f) = &input {
            check_same_size(f)?;
        }
        let p = playback::Playback::new(input, load, fps, cli.rate, out);
        return Ok((Content::Playback(Box::new(p)), fx));
    }
    let items: Vec<PathBuf> = collect_inputs(cli, &specs)?
        .into_iter()
        .map(|(_, p)| p)
        .collect();
    let aux = aux_images(cli)?;
    if !aux.is_empty() && items.len() > 1 {
        return Err(rejected("--view takes --aux with a single image only"));
    }
    let stills = stills::Stills::new(items, aux, load, out);
    Ok((Content::Stills(Box::new(stills)), fx))
}

/// `fxrun ... --view`.
pub(crate) fn run_view(cli: &Cli) -> Result<(), Fail> {
    if let Some(why) = refusal(cli) {
        return Err(rejected(why));
    }
    let mut actions = Vec::new();
    for a in &cli.view_do {
        actions.push(script::parse(a).map_err(rejected)?);
    }
    let script = match cli.view_frames {
        Some(0) => return Err(rejected("--view-frames: give at least 1 frame")),
        Some(n) => {
            if let Some((k, _)) = actions.iter().find(|(k, _)| *k > n) {
                return Err(rejected(format!(
                    "--view-do: frame {k} is after the last frame shown ({n}, --view-frames)"
                )));
            }
            Some(script::Script::new(n, actions))
        }
        None if !actions.is_empty() => {
            return Err(rejected("--view-do needs --view-frames N"));
        }
        None => None,
    };
    let Some(display) = display_named() else {
        return Err(rejected(
            "--view needs a display, and none is set (DISPLAY or WAYLAND_DISPLAY): run it in a desktop session, or under a virtual X server (xvfb-run -a fxrun ... --view)",
        ));
    };
    let event_loop = winit::event_loop::EventLoop::<UserEvent>::with_user_event()
        .build()
        .map_err(|e| {
            // winit's message names its own source file first: keep the reason.
            let text = e.to_string();
            let reason = text.rsplit(": ").next().unwrap_or(&text).to_string();
            log::info!("--view: {text}");
            rejected(format!(
                "--view: cannot open the display ({display}): {reason}; is the display server running?"
            ))
        })?;
    let ctx = fxgraph::gpu::context::GpuContext::new(&adapter_choice(&cli.adapter))
        .map_err(RunError::from)?;
    let engine = Engine::new(ctx);
    let (content, fx) = content_for(cli, &engine)?;
    let proxy = event_loop.create_proxy();
    let mut viewer = app::Viewer::new(cli.clone(), engine, content, fx, script, proxy)?;
    let ran = event_loop.run_app(&mut viewer);
    let result = viewer.finish();
    ran.map_err(|e| Fail {
        code: 2,
        message: format!("--view: the window's event loop failed: {e}"),
    })?;
    result
}
