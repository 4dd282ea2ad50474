//! The control panel (egui), generated from the effect's parameter metadata:
//!
//! - effect parameters (`FLOAT`, `INT`, `BOOL`, `ENUM`, vectors) with their ranges,
//!   defaults and descriptions, and every shader parameter of every pass
//!   (`Prepared::params()`: type, range, `@default`, description) as sliders,
//!   drag values, colour pickers (vectors named `*color*`) and check boxes; a reset
//!   per parameter; "copy as --set";
//! - the pass list (size, format, GPU time) with the output, the input and the AUX
//!   images, to inspect one, and how it is shown (shade, range);
//! - the view (fit, 1:1, split, exposure, clipping), playback, the keys.
//!
//! Changes come back as [`UiEvent`]s, applied after the frame by the code the keys
//! and scripted actions use: nothing here changes the effect.

use super::command::Command;
use super::fx::effect_value_text;
use super::ui_state::{ImageInput, UiState, PANEL_WIDTH};
use crate::gpu::executor::ParamInfo;
use crate::graph::EffectParam;
use crate::script::types::{format_value, Format, ParamType};
use crate::view::inspect::Target;
pub use crate::view::model::Model;
use crate::view::present::Shade;
use egui::{Color32, RichText};

/// A change asked for in the panel.
#[derive(Debug, Clone, PartialEq)]
pub enum UiEvent {
    /// Set parameter KEY to a `--set` value text.
    Set(String, String),
    Reset(String),
    Command(Command),
    Inspect(Target),
    CopySet,
    /// Set the range to the shown texture's smallest and largest value.
    AutoRange,
}

/// The keys (also in docs/cli.md).
const KEYS: &[(&str, &str)] = &[
    ("Right / Left", "next / previous image or frame"),
    ("Home", "first image or frame"),
    ("Space", "play / pause a sequence"),
    (
        "F, 1, + / -",
        "fit, 1:1 pixels, zoom (wheel: zoom at the pointer)",
    ),
    ("drag", "pan the image (scenes: orbit; right drag: pan)"),
    (
        "W A S D, E Q",
        "scenes: fly (Shift: faster); H: back to the camera",
    ),
    ("Down / Up", "inspect the next / previous pass"),
    ("B", "before/after split"),
    ("P, F12", "screenshot (what is shown, full resolution)"),
    ("Tab", "show / hide this panel"),
    ("Esc, Ctrl+Q", "quit"),
];

/// The panel and the image area; returns the mouse over the image area.
pub fn show(
    ui: &mut egui::Ui,
    m: &Model,
    state: &mut UiState,
    out: &mut Vec<UiEvent>,
) -> ImageInput {
    if state.panel {
        egui::Panel::right("fxrun viewer panel")
            .default_size(PANEL_WIDTH)
            .resizable(true)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| contents(ui, m, state, out));
            });
    }
    let mut input = ImageInput::default();
    egui::CentralPanel::no_frame().show(ui, |ui| {
        let rect = ui.max_rect();
        let ppp = ui.ctx().pixels_per_point();
        input.area = [rect.min.x, rect.min.y, rect.width(), rect.height()];
        let r = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let d = r.drag_delta() * ppp;
        input.drag = [d.x, d.y];
        input.primary = r.dragged_by(egui::PointerButton::Primary);
        input.double_click = r.double_clicked();
        input.hover = r.hover_pos().map(|p| [p.x * ppp, p.y * ppp]);
        if r.hovered() {
            input.scroll = ui.input(|i| {
                i.events
                    .iter()
                    .map(|e| match e {
                        egui::Event::MouseWheel { unit, delta, .. } => match unit {
                            egui::MouseWheelUnit::Line => delta.y,
                            egui::MouseWheelUnit::Point => delta.y / 50.0,
                            egui::MouseWheelUnit::Page => delta.y * 10.0,
                        },
                        _ => 0.0,
                    })
                    .sum()
            });
        }
    });
    input
}

fn contents(ui: &mut egui::Ui, m: &Model, state: &mut UiState, out: &mut Vec<UiEvent>) {
    ui.heading("fxrun viewer");
    ui.label(&m.caption);
    let frame = m
        .frame_ms
        .map(|t| format!(" · last frame {t:.1} ms"))
        .unwrap_or_default();
    ui.label(RichText::new(format!("{}{frame}", m.adapter)).small());
    if let Some(fps) = &m.fps {
        ui.label(RichText::new(fps.text()).small());
    }
    if let Some(e) = &state.error {
        ui.separator();
        ui.label(RichText::new("error (the last good image stays):").color(Color32::LIGHT_RED));
        ui.label(
            RichText::new(e.trim_end())
                .monospace()
                .color(Color32::LIGHT_RED),
        );
    }
    if !state.status.is_empty() {
        ui.label(RichText::new(&state.status).small());
    }
    ui.separator();
    view_section(ui, m, state, out);
    egui::CollapsingHeader::new("Parameters")
        .default_open(true)
        .show(ui, |ui| params_section(ui, m, out));
    egui::CollapsingHeader::new("Passes")
        .default_open(true)
        .show(ui, |ui| passes_section(ui, m, state, out));
    egui::CollapsingHeader::new("Keys").show(ui, |ui| {
        egui::Grid::new("keys").show(ui, |ui| {
            for (k, what) in KEYS {
                ui.label(RichText::new(*k).monospace());
                ui.label(*what);
                ui.end_row();
            }
        });
    });
}

fn view_section(ui: &mut egui::Ui, m: &Model, state: &mut UiState, out: &mut Vec<UiEvent>) {
    ui.horizontal(|ui| {
        if ui.selectable_label(state.fit, "Fit").clicked() {
            out.push(UiEvent::Command(Command::Fit));
        }
        let one = !state.fit && state.zoom == 1.0;
        if ui.selectable_label(one, "1:1").clicked() {
            out.push(UiEvent::Command(Command::OneToOne));
        }
        if !state.fit {
            ui.label(format!("{:.0} %", state.zoom * 100.0));
        }
        if ui.button("Screenshot").clicked() {
            out.push(UiEvent::Command(Command::Screenshot));
        }
    });
    let mut split = state.split.is_some();
    ui.horizontal(|ui| {
        if ui.checkbox(&mut split, "before | after").changed() {
            state.split = split.then_some(0.5);
        }
        if let Some(s) = &mut state.split {
            ui.add(egui::Slider::new(s, 0.0..=1.0).show_value(false));
        }
    });
    if m.shown_format.is_some_and(Format::is_float) {
        ui.horizontal(|ui| {
            ui.label("exposure");
            ui.add(egui::Slider::new(&mut state.exposure, -10.0..=10.0).suffix(" EV"));
        });
        ui.checkbox(
            &mut state.mark_clipping,
            "mark values above 1 (they clip on this display)",
        );
    }
    if let Some(f) = m.output_format {
        let what = if f.is_float() {
            "linear light, as an EXR stores it; shown sRGB-encoded with the exposure"
        } else {
            "the bytes a file of this format gets"
        };
        ui.label(RichText::new(format!("output {f}: {what}")).small());
    }
    if let Some(playing) = m.playing {
        let play = if playing { "pause" } else { "play" };
        command_buttons(
            ui,
            &[
                ("|<", "first frame (Home)", Command::First),
                ("<", "previous frame (Left)", Command::Prev),
                (play, "Space", Command::PlayPause),
                (">", "next frame (Right)", Command::Next),
            ],
            out,
        );
    } else if !m.scene {
        command_buttons(
            ui,
            &[
                ("<", "previous image (Left)", Command::Prev),
                (">", "next image (Right)", Command::Next),
            ],
            out,
        );
    }
    if m.scene && ui.button("camera of the run (H)").clicked() {
        out.push(UiEvent::Command(Command::CameraHome));
    }
    ui.checkbox(&mut state.continuous, "run the effect every frame");
}

/// A row of buttons, each (label, hover text, the command it gives).
fn command_buttons(ui: &mut egui::Ui, buttons: &[(&str, &str, Command)], out: &mut Vec<UiEvent>) {
    ui.horizontal(|ui| {
        for &(label, hover, command) in buttons {
            if ui.button(label).on_hover_text(hover).clicked() {
                out.push(UiEvent::Command(command));
            }
        }
    });
}

/// A number, a vector or a colour; true when changed.
fn value_widget(
    ui: &mut egui::Ui,
    name: &str,
    integer: bool,
    (range, step): (Option<(f64, f64)>, Option<f64>),
    v: &mut [f64],
) -> bool {
    let lname = name.to_lowercase();
    if (v.len() == 3 || v.len() == 4) && (lname.contains("color") || lname.contains("colour")) {
        let mut rgb = [v[0] as f32, v[1] as f32, v[2] as f32];
        if ui.color_edit_button_rgb(&mut rgb).changed() {
            for (d, s) in v.iter_mut().zip(rgb) {
                *d = s as f64;
            }
            return true;
        }
    }
    // An integer that is 0 or 1: a switch.
    if integer && v.len() == 1 && range == Some((0.0, 1.0)) {
        let mut on = v[0] != 0.0;
        if ui.checkbox(&mut on, "").changed() {
            v[0] = f64::from(u8::from(on));
            return true;
        }
        return false;
    }
    let mut changed = false;
    for x in v.iter_mut() {
        changed |= match range {
            Some((lo, hi)) if slider_range(lo, hi) => {
                let log = lo >= 0.0 && hi > 100.0 * lo.max(1e-3) && hi > 10.0;
                let mut s = egui::Slider::new(x, lo..=hi).logarithmic(log);
                if integer {
                    s = s.integer();
                }
                if let Some(step) = step {
                    s = s.step_by(step);
                }
                ui.add(s).changed()
            }
            _ => {
                let speed = step.unwrap_or((x.abs() * 0.01).max(if integer { 0.1 } else { 0.001 }));
                let mut d = egui::DragValue::new(x).speed(speed);
                if let Some((lo, hi)) = range {
                    d = d.range(lo..=hi);
                }
                if integer {
                    d = d.max_decimals(0);
                }
                ui.add(d).changed()
            }
        };
    }
    changed
}

/// A finite range a slider can cover.
fn slider_range(lo: f64, hi: f64) -> bool {
    lo.is_finite() && hi.is_finite() && hi > lo
}

/// The effect's parameters, then every pass's, then "copy as --set" (an
/// application's own panel may show it alone, with a [`Model::for_effect`]).
pub fn params_section(ui: &mut egui::Ui, m: &Model, out: &mut Vec<UiEvent>) {
    for p in &m.effect_params {
        effect_param_row(ui, p, out);
    }
    let mut pass = "";
    for (i, p) in m.params.iter().enumerate() {
        let (path, _) = p.name.rsplit_once('.').unwrap_or(("", &p.name));
        if path != pass {
            pass = path;
            ui.label(RichText::new(path).small().weak());
        }
        pass_param_row(ui, p, &m.defaults[i], m.set[i], out);
    }
    if m.params.is_empty() && m.effect_params.is_empty() {
        ui.label("no parameters");
    }
    if ui
        .button("copy as --set")
        .on_hover_text("the values set, as command-line arguments (clipboard and stdout)")
        .clicked()
    {
        out.push(UiEvent::CopySet);
    }
    if let Some(text) = &m.set_args {
        ui.label(RichText::new(text).monospace().small());
    }
}

/// ", range [a, b]" when there is one.
fn range_text(range: Option<(f64, f64)>) -> String {
    range
        .map(|(a, b)| format!(", range [{a}, {b}]"))
        .unwrap_or_default()
}

/// One effect parameter (`EFFECT.NAME`): its control and a reset.
fn effect_param_row(ui: &mut egui::Ui, p: &EffectParam, out: &mut Vec<UiEvent>) {
    let key = format!("{}.{}", p.effect, p.name);
    let hover = format!(
        "{key} ({}){}\ndefault {}\n{}",
        p.ty.name(),
        range_text(p.range),
        effect_value_text(p, &p.default),
        p.description
    );
    ui.horizontal(|ui| {
        ui.label(RichText::new(&key).strong()).on_hover_text(&hover);
        let mut v = p.value.clone();
        if effect_value_widget(ui, p, &key, &mut v) {
            out.push(UiEvent::Set(key.clone(), effect_value_text(p, &v)));
        }
        if p.value != p.default && ui.small_button("reset").clicked() {
            out.push(UiEvent::Reset(key.clone()));
        }
    });
}

/// The control of an effect parameter by its type (a switch, a choice, a
/// number or vector); true when changed.
fn effect_value_widget(ui: &mut egui::Ui, p: &EffectParam, key: &str, v: &mut [f64]) -> bool {
    match &p.ty {
        ParamType::Bool => {
            let mut b = v[0] != 0.0;
            let c = ui.checkbox(&mut b, "").changed();
            v[0] = f64::from(u8::from(b));
            c
        }
        ParamType::Enum(names) => {
            let mut i = v[0] as usize;
            let before = i;
            egui::ComboBox::from_id_salt(key)
                .selected_text(names.get(i).cloned().unwrap_or_default())
                .show_ui(ui, |ui| {
                    for (j, n) in names.iter().enumerate() {
                        ui.selectable_value(&mut i, j, n);
                    }
                });
            v[0] = i as f64;
            i != before
        }
        ty => value_widget(ui, &p.name, *ty == ParamType::Int, (p.range, p.step), v),
    }
}

/// One shader parameter of a pass (`PASS.NAME`, shown by its field name, in
/// bold when set): its control and a reset to `default`.
fn pass_param_row(
    ui: &mut egui::Ui,
    p: &ParamInfo,
    default: &[f64],
    set: bool,
    out: &mut Vec<UiEvent>,
) {
    let field = p.name.rsplit_once('.').map_or(p.name.as_str(), |(_, f)| f);
    let hover = format!(
        "{} ({}){}\nshader @default {}\n{}{}",
        p.name,
        p.ty,
        range_text(p.range),
        p.default
            .as_ref()
            .map_or_else(|| "none".to_string(), |d| format_value(d)),
        p.description,
        if set { "\n(set here or by --set)" } else { "" }
    );
    ui.horizontal(|ui| {
        let label = if set {
            RichText::new(field).strong()
        } else {
            RichText::new(field)
        };
        ui.label(label).on_hover_text(&hover);
        let mut v = p.value.clone();
        let integer = p.ty.contains("i32") || p.ty.contains("u32");
        if value_widget(ui, field, integer, (p.range, None), &mut v) {
            out.push(UiEvent::Set(p.name.clone(), format_value(&v)));
        }
        if v != default && ui.small_button("reset").clicked() {
            out.push(UiEvent::Reset(p.name.clone()));
        }
    });
}

/// The pass list (the output, each pass with its size, format and GPU time,
/// the input, the AUX images) to pick what is inspected, and how it is shown.
pub fn passes_section(ui: &mut egui::Ui, m: &Model, state: &mut UiState, out: &mut Vec<UiEvent>) {
    let mut pick = |ui: &mut egui::Ui, t: Target, label: String| {
        if ui.radio(state.inspect.target == t, label).clicked() {
            out.push(UiEvent::Inspect(t));
        }
    };
    egui::Grid::new("passes").striped(true).show(ui, |ui| {
        pick(ui, Target::Output, "output".into());
        ui.label(m.output_format.map(|f| f.to_string()).unwrap_or_default());
        ui.end_row();
        for r in &m.rows {
            pick(ui, Target::Pass(r.index), r.path.clone());
            let time = match r.gpu_ms {
                Some(t) => format!("{t:.2} ms"),
                None if m.timed => "-".into(),
                None => String::new(),
            };
            ui.label(
                RichText::new(format!("{}x{} {} {time}", r.width, r.height, r.format)).small(),
            );
            ui.end_row();
        }
        pick(ui, Target::Input, "input".into());
        ui.end_row();
        for (n, f) in &m.aux {
            pick(ui, Target::Aux(n.clone()), format!("AUX.{n}"));
            ui.label(RichText::new(f.to_string()).small());
            ui.end_row();
        }
    });
    if !m.timed {
        ui.label(
            RichText::new("GPU times appear after a few frames (timestamp queries), where the adapter has them")
                .small()
                .weak(),
        );
    }
    if state.inspect.target == Target::Output {
        return;
    }
    ui.horizontal(|ui| {
        ui.label("show as");
        let name = |s: Option<Shade>| match s {
            None => "auto",
            Some(Shade::Codes) => "8-bit codes",
            Some(Shade::Colour) => "colour",
            Some(Shade::Data) => "data (range)",
        };
        egui::ComboBox::from_id_salt("shade")
            .selected_text(name(state.inspect.shade))
            .show_ui(ui, |ui| {
                for s in [
                    None,
                    Some(Shade::Codes),
                    Some(Shade::Colour),
                    Some(Shade::Data),
                ] {
                    ui.selectable_value(&mut state.inspect.shade, s, name(s));
                }
            });
    });
    ui.horizontal(|ui| {
        ui.label("range");
        let (lo, hi) = &mut state.inspect.range;
        ui.add(egui::DragValue::new(lo).speed(0.01));
        ui.add(egui::DragValue::new(hi).speed(0.01));
        if ui.button("auto").clicked() {
            out.push(UiEvent::AutoRange);
        }
    });
}
