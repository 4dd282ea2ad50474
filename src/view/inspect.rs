//! Inspecting: what is shown instead of the output (a pass of the plan, the
//! effect's input, a scene's G-buffer image), the pass list with each pass's size,
//! format and GPU time, and the ranges single-channel and data images are shown
//! in. A pass's output is kept by the library (`Prepared::inspect`), which copies
//! it after the pass without changing the plan.
//!
//! Ranges (shown as 0..1, data shade): single-channel and two-channel textures
//! [0, 1]; a scene's `depth` [near, far] of the camera, `normal` [-1, 1],
//! `position` ± the scene's size; "auto" reads the texture back and takes the
//! smallest and largest finite value.

use super::present::{auto_shade, Shade};
use crate::gpu::context::GpuContext;
use crate::gpu::executor::Prepared;
use crate::gpu::transfer::unpack_rgb10a2;
use crate::script::types::Format;

/// What is shown.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// The effect's output (a file's content).
    Output,
    /// The output of pass `i` of the plan (`plan.passes[i]`).
    Pass(usize),
    /// The effect's input (an image, a sequence frame, a scene's render).
    Input,
    /// An auxiliary image (`--aux`, a scene's G-buffer).
    Aux(String),
}

impl Target {
    /// By name: a pass's path or its last part (in `prepared`'s plan), `output`,
    /// `input`, `aux:NAME` (`--view-do inspect NAME`).
    pub fn by_name(prepared: Option<&Prepared>, name: &str) -> Result<Target, String> {
        Ok(match name {
            "output" => Target::Output,
            "input" => Target::Input,
            _ if name.starts_with("aux:") => Target::Aux(name[4..].to_string()),
            _ => {
                let p = prepared.ok_or("no effect is planned")?;
                let i = p
                    .plan
                    .passes
                    .iter()
                    .position(|q| q.path == name || q.path.rsplit('/').next() == Some(name))
                    .ok_or_else(|| format!("inspect {name}: no such pass"))?;
                Target::Pass(i)
            }
        })
    }

    /// The next (`forward`) or previous entry of a list of `passes` passes after
    /// the output; other targets stay.
    pub fn step(&self, passes: usize, forward: bool) -> Target {
        match (self, forward) {
            (Target::Pass(i), true) if i + 1 < passes => Target::Pass(i + 1),
            (Target::Pass(0), false) => Target::Output,
            (Target::Pass(i), false) => Target::Pass(i - 1),
            (Target::Output, true) if passes > 0 => Target::Pass(0),
            (t, _) => t.clone(),
        }
    }
}

/// The inspection settings of the panel.
pub struct Inspect {
    pub target: Target,
    /// `None`: as the format suggests.
    pub shade: Option<Shade>,
    pub range: (f32, f32),
}

impl Default for Inspect {
    fn default() -> Self {
        Inspect {
            target: Target::Output,
            shade: None,
            range: (0.0, 1.0),
        }
    }
}

/// One row of the pass list.
pub struct PassRow {
    pub index: usize,
    pub path: String,
    pub width: u32,
    pub height: u32,
    pub format: Format,
    /// From the last timed frame (timestamp queries), when the adapter has them.
    pub gpu_ms: Option<f64>,
}

/// The plan's passes in execution order, with the last GPU times read.
pub fn pass_rows(p: &Prepared) -> Vec<PassRow> {
    let times = p.gpu_timings();
    p.plan
        .passes
        .iter()
        .enumerate()
        .map(|(i, pass)| PassRow {
            index: i,
            path: pass.path.clone(),
            width: pass.desc.width,
            height: pass.desc.height,
            format: pass.desc.format,
            gpu_ms: times
                .iter()
                .find(|t| t.path == pass.path)
                .and_then(|t| t.gpu_ms),
        })
        .collect()
}

/// The default range of an auxiliary image (see the module's documentation).
pub fn aux_range(name: &str, depth: (f32, f32), size: f32) -> (f32, f32) {
    match name {
        "depth" => depth,
        "normal" => (-1.0, 1.0),
        "position" => (-size, size),
        _ => (0.0, 1.0),
    }
}

/// The shade an inspected texture is shown in: the panel's, else the format's.
pub fn shade_of(inspect: &Inspect, format: Format) -> Shade {
    inspect.shade.unwrap_or(auto_shade(format))
}

/// Channels and linear float values of a texture's texels (RGBA formats as 4
/// channels, R as 1, RG as 2; 8-bit codes as code / 255).
pub fn texel_values(raw: &[u8], format: Format) -> (usize, Vec<f32>) {
    let half = |c: &[u8]| half::f16::from_le_bytes([c[0], c[1]]).to_f32();
    let single = |c: &[u8]| f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    match format {
        Format::Rgba8 | Format::Rgba8Srgb => (4, raw.iter().map(|&b| b as f32 / 255.0).collect()),
        Format::R8 => (1, raw.iter().map(|&b| b as f32 / 255.0).collect()),
        Format::Rgba16f => (4, raw.chunks_exact(2).map(half).collect()),
        Format::R16f => (1, raw.chunks_exact(2).map(half).collect()),
        Format::Rg16f => (2, raw.chunks_exact(2).map(half).collect()),
        Format::Rgba32f => (4, raw.chunks_exact(4).map(single).collect()),
        Format::R32f => (1, raw.chunks_exact(4).map(single).collect()),
        Format::Rg32f => (2, raw.chunks_exact(4).map(single).collect()),
        Format::Rgb10a2 => (4, raw.chunks_exact(4).flat_map(unpack_rgb10a2).collect()),
    }
}

/// The smallest and largest finite value of the colour channels of a texture.
pub fn value_range(ctx: &GpuContext, t: &wgpu::Texture, format: Format) -> Option<(f32, f32)> {
    let raw = ctx.read_texture(t).ok()?;
    let (ch, values) = texel_values(&raw, format);
    let colour = ch.min(3);
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    for px in values.chunks_exact(ch) {
        for &v in &px[..colour] {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    (lo <= hi).then_some(if lo == hi { (lo, lo + 1.0) } else { (lo, hi) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_values_decode_every_format() {
        assert_eq!(texel_values(&[0, 255], Format::R8), (1, vec![0.0, 1.0]));
        let h = half::f16::from_f32(-2.5).to_le_bytes();
        assert_eq!(texel_values(&h, Format::R16f), (1, vec![-2.5]));
        let v: u32 = 1023 | (512 << 10) | (3 << 30);
        let (ch, px) = texel_values(&v.to_le_bytes(), Format::Rgb10a2);
        assert_eq!(ch, 4);
        assert_eq!(px[0], 1.0);
        assert!((px[1] - 512.0 / 1023.0).abs() < 1e-6);
        assert_eq!(px[3], 1.0);
    }
}
