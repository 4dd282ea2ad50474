//! The uniform buffer of a pass: the standard values the runtime fills in under
//! reserved field names (`out_size`, `frame`, `time`, `jitter`, ...; see
//! docs/shaders.md), and the layout that writes parameters and standard values
//! into the buffer's bytes.

use super::reflect::FieldType;
use crate::script::types::Value;

/// Values the runtime provides under reserved uniform names (see docs/shaders.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StdValue {
    /// `out_size`: output size in pixels.
    OutSize,
    /// `out_texel`: 1 / output size.
    OutTexel,
    /// `<input>_size`
    InputSize(usize),
    /// `<input>_texel`
    InputTexel(usize),
    /// `frame`: frame index (0 for a still image).
    Frame,
    /// `time`: seconds (frame / fps).
    Time,
    /// `subframe`: which of the outputs of one input frame is being produced
    /// (0 unless the stream's rate is above 1, e.g. field-rate deinterlacing).
    Subframe,
    /// `near`, `far`: camera planes (renderer input; 0.1 and 100 otherwise).
    Near,
    Far,
    /// `proj`, `inv_proj`: camera projection (identity without a renderer).
    Proj,
    InvProj,
    /// `jitter`: the frame's sub-pixel jitter in pixels (offset of the sample
    /// position from the pixel centre, x right, y down; 0 without jitter).
    Jitter,
    /// `cut`: 1 on the first frame of a new shot (the camera cut since the
    /// previous frame: history from before it shows another view), else 0.
    Cut,
    /// `out_size_texel`: `(w, h, 1/w, 1/h)` of the output (the layout of slang's
    /// `OutputSize`).
    OutSize4,
    /// `<input>_size_texel`: `(w, h, 1/w, 1/h)` of an input.
    InputSize4(usize),
    /// `final_size_texel`: `(w, h, 1/w, 1/h)` of the effect's output image.
    FinalSize4,
    /// `frame_mod_N_count`: `frame % N`.
    FrameMod(u32),
    /// `frame_direction`: 1 (frames run forward).
    FrameDirection,
    /// `rotation`: 0 (images are never rotated).
    Rotation,
    /// `total_subframes`: 1, `current_subframe`: 1 (one output per frame).
    TotalSubframes,
    CurrentSubframe,
    /// `in_aspect`: width / height of the effect input.
    InAspect,
    /// `mvp`: the orthographic projection of the unit square onto clip space
    /// (slang's `MVP`).
    Mvp,
    /// `fps`: the input's frames per second (slang's `OriginalFPS`).
    Fps,
    /// `frame_time_ms`: milliseconds from the previous frame, 1000 / fps
    /// rounded, 0 on the first frame (slang's `FrameTimeDelta`).
    FrameTimeMs,
    /// `frontend_*`: what a RetroArch frontend tells its presets about the
    /// display and the device, as librashader binds them by default (an SDR
    /// display, no sensors): `frontend_hdr_mode` 0, `frontend_brightness_nits`
    /// 200, `frontend_expand_gamut`, `frontend_scanlines`,
    /// `frontend_inverse_tonemap`, `frontend_hdr10`, `frontend_subpixel_layout`
    /// 0, `frontend_gyroscope`, `frontend_accelerometer`,
    /// `frontend_accelerometer_rest` (0, 0, 0).
    Frontend(f32),
}

#[derive(Debug, Clone, PartialEq)]
pub enum UniformSource {
    Param(Value),
    Std(StdValue),
}

#[derive(Debug, Clone, PartialEq)]
pub struct UniformField {
    pub name: String,
    pub offset: u32,
    pub ty: FieldType,
    pub source: UniformSource,
}

/// How to fill a pass's uniform buffer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UniformLayout {
    pub size: u32,
    pub fields: Vec<UniformField>,
}

/// Per-frame values for [`UniformLayout::write`].
#[derive(Debug, Clone, Default)]
pub struct StdContext {
    pub out_size: (u32, u32),
    pub input_sizes: Vec<(u32, u32)>,
    pub frame: u64,
    pub time: f64,
    pub subframe: u32,
    pub near: f32,
    pub far: f32,
    pub proj: [f32; 16],
    pub inv_proj: [f32; 16],
    pub jitter: [f32; 2],
    pub cut: bool,
    /// Size of the effect's input and output images.
    pub in_size: (u32, u32),
    pub final_size: (u32, u32),
    /// The input's frames per second.
    pub fps: f64,
}

/// `(w, h, 1/w, 1/h)`.
fn size4(s: (u32, u32)) -> Vec<f64> {
    let (w, h) = (f64::from(s.0.max(1)), f64::from(s.1.max(1)));
    vec![w, h, 1.0 / w, 1.0 / h]
}

/// Column-major orthographic projection of (0..1, 0..1) onto clip space.
const MVP: [f64; 16] = [
    2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, -1.0, 0.0, 1.0,
];

impl UniformLayout {
    /// The uniform buffer bytes for one run of the pass.
    pub fn write(&self, ctx: &StdContext) -> Vec<u8> {
        let mut out = vec![0u8; self.size as usize];
        for f in &self.fields {
            let values: Vec<f64> = match &f.source {
                UniformSource::Param(v) => v.clone(),
                UniformSource::Std(s) => match *s {
                    StdValue::OutSize => vec![ctx.out_size.0 as f64, ctx.out_size.1 as f64],
                    StdValue::OutTexel => {
                        vec![1.0 / ctx.out_size.0 as f64, 1.0 / ctx.out_size.1 as f64]
                    }
                    StdValue::InputSize(i) => {
                        let s = ctx.input_sizes.get(i).copied().unwrap_or((1, 1));
                        vec![s.0 as f64, s.1 as f64]
                    }
                    StdValue::InputTexel(i) => {
                        let s = ctx.input_sizes.get(i).copied().unwrap_or((1, 1));
                        vec![1.0 / s.0 as f64, 1.0 / s.1 as f64]
                    }
                    StdValue::Frame => vec![ctx.frame as f64],
                    StdValue::Time => vec![ctx.time],
                    StdValue::Subframe => vec![ctx.subframe as f64],
                    StdValue::Near => vec![ctx.near as f64],
                    StdValue::Far => vec![ctx.far as f64],
                    StdValue::Proj => ctx.proj.iter().map(|&x| x as f64).collect(),
                    StdValue::InvProj => ctx.inv_proj.iter().map(|&x| x as f64).collect(),
                    StdValue::Jitter => vec![ctx.jitter[0] as f64, ctx.jitter[1] as f64],
                    StdValue::Cut => vec![if ctx.cut { 1.0 } else { 0.0 }],
                    other => slang_value(other, ctx),
                },
            };
            for (i, &x) in values.iter().take(f.ty.components()).enumerate() {
                let at = f.offset as usize + 4 * i;
                let bytes = match f.ty {
                    FieldType::F32(_) | FieldType::Mat4 => (x as f32).to_le_bytes(),
                    FieldType::I32(_) => (x as i32).to_le_bytes(),
                    FieldType::U32(_) => (x.max(0.0) as u32).to_le_bytes(),
                };
                out[at..at + 4].copy_from_slice(&bytes);
            }
        }
        out
    }

    /// True when a field changes from frame to frame.
    pub fn is_dynamic(&self) -> bool {
        self.fields.iter().any(|f| {
            matches!(
                f.source,
                UniformSource::Std(
                    StdValue::Frame
                        | StdValue::Time
                        | StdValue::Subframe
                        | StdValue::Jitter
                        | StdValue::Cut
                        | StdValue::FrameMod(_)
                        | StdValue::Fps
                        | StdValue::FrameTimeMs
                )
            )
        })
    }
}

/// The values slang presets read (docs/slang.md).
fn slang_value(v: StdValue, ctx: &StdContext) -> Vec<f64> {
    match v {
        StdValue::OutSize4 => size4(ctx.out_size),
        StdValue::InputSize4(i) => size4(ctx.input_sizes.get(i).copied().unwrap_or((1, 1))),
        StdValue::FinalSize4 => size4(ctx.final_size),
        StdValue::FrameMod(n) => vec![(ctx.frame % u64::from(n.max(1))) as f64],
        StdValue::FrameDirection | StdValue::TotalSubframes | StdValue::CurrentSubframe => {
            vec![1.0]
        }
        StdValue::Rotation => vec![0.0],
        StdValue::InAspect => {
            vec![f64::from(ctx.in_size.0.max(1)) / f64::from(ctx.in_size.1.max(1))]
        }
        StdValue::Mvp => MVP.to_vec(),
        StdValue::Fps => vec![ctx.fps],
        StdValue::FrameTimeMs if ctx.frame == 0 || ctx.fps <= 0.0 => vec![0.0],
        StdValue::FrameTimeMs => vec![(1000.0 / ctx.fps).round()],
        StdValue::Frontend(v) => vec![f64::from(v); 3],
        _ => Vec::new(),
    }
}

/// The standard value a reserved uniform name stands for, given the pass inputs.
pub(crate) fn std_value(name: &str, inputs: &[String]) -> Option<(StdValue, &'static [FieldType])> {
    const V2: &[FieldType] = &[FieldType::F32(2)];
    const V4: &[FieldType] = &[FieldType::F32(4)];
    const SCALAR: &[FieldType] = &[FieldType::F32(1), FieldType::U32(1), FieldType::I32(1)];
    const F1: &[FieldType] = &[FieldType::F32(1)];
    const M4: &[FieldType] = &[FieldType::Mat4];
    Some(match name {
        "out_size" => (StdValue::OutSize, V2),
        "out_texel" => (StdValue::OutTexel, V2),
        "frame" => (StdValue::Frame, SCALAR),
        "time" => (StdValue::Time, F1),
        "subframe" => (StdValue::Subframe, SCALAR),
        "near" => (StdValue::Near, F1),
        "far" => (StdValue::Far, F1),
        "proj" => (StdValue::Proj, M4),
        "inv_proj" => (StdValue::InvProj, M4),
        "jitter" => (StdValue::Jitter, V2),
        "cut" => (StdValue::Cut, SCALAR),
        "out_size_texel" => (StdValue::OutSize4, V4),
        "final_size_texel" => (StdValue::FinalSize4, V4),
        "frame_direction" => (StdValue::FrameDirection, SCALAR),
        "rotation" => (StdValue::Rotation, SCALAR),
        "total_subframes" => (StdValue::TotalSubframes, SCALAR),
        "current_subframe" => (StdValue::CurrentSubframe, SCALAR),
        "in_aspect" => (StdValue::InAspect, F1),
        "mvp" => (StdValue::Mvp, M4),
        "fps" => (StdValue::Fps, F1),
        "frame_time_ms" => (StdValue::FrameTimeMs, SCALAR),
        "frontend_brightness_nits" => (StdValue::Frontend(200.0), SCALAR),
        "frontend_hdr_mode"
        | "frontend_expand_gamut"
        | "frontend_scanlines"
        | "frontend_inverse_tonemap"
        | "frontend_hdr10"
        | "frontend_subpixel_layout" => (StdValue::Frontend(0.0), SCALAR),
        "frontend_gyroscope" | "frontend_accelerometer" | "frontend_accelerometer_rest" => {
            (StdValue::Frontend(0.0), &[FieldType::F32(3)])
        }
        _ => {
            if let Some(n) = name
                .strip_prefix("frame_mod_")
                .and_then(|n| n.strip_suffix("_count"))
                .and_then(|n| n.parse().ok())
            {
                return Some((StdValue::FrameMod(n), SCALAR));
            }
            for (i, inp) in inputs.iter().enumerate() {
                if name.strip_prefix(inp.as_str()) == Some("_size") {
                    return Some((StdValue::InputSize(i), V2));
                }
                if name.strip_prefix(inp.as_str()) == Some("_texel") {
                    return Some((StdValue::InputTexel(i), V2));
                }
                if name.strip_prefix(inp.as_str()) == Some("_size_texel") {
                    return Some((StdValue::InputSize4(i), V4));
                }
            }
            return None;
        }
    })
}
