//! What a conversion needs to know about a stream's frames: sizes, depth, chroma
//! siting and taps, the matrix and range as coefficients; and the uniform block
//! the shaders read (`shaders/yuv/yuv_params.wgsl`).

use crate::script::types::Format;

/// Horizontal chroma siting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChromaSiting {
    /// Not subsampled across (4:4:4).
    Full,
    /// Halfway between two luma columns.
    Between,
    /// On the even luma columns.
    CoSited,
}

/// Upsampling: a luma row's chroma is `row[i0] + w * (row[i1] - row[i0])`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpTap {
    pub i0: u32,
    pub i1: u32,
    pub w: f32,
}

/// Downsampling: a chroma row is the sum of up to three luma rows' values, weighted.
pub type DownTap = [(u32, f32); 3];

/// The code scales of a range at a depth and the matrix (the CPU conversion's
/// `Coeffs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YuvCoefficients {
    /// Luma code of black and codes per unit.
    pub y_off: f32,
    pub y_scale: f32,
    /// Chroma code of zero and codes per unit of Pb / Pr.
    pub c_mid: f32,
    pub c_scale: f32,
    /// The largest code, `2^depth - 1`.
    pub max: f32,
    pub kr: f32,
    pub kg: f32,
    pub kb: f32,
    /// R' = Y' + rv Pr; G' = Y' + gu Pb + gv Pr; B' = Y' + bu Pb.
    pub rv: f32,
    pub gu: f32,
    pub gv: f32,
    pub bu: f32,
}

/// The frames of one stream, as the conversion passes see them.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneLayout {
    pub width: u32,
    pub height: u32,
    /// The size of each chroma plane; `(0, 0)` for luma-only frames.
    pub chroma_width: u32,
    pub chroma_height: u32,
    /// Bits per sample, 8 to 16 (one byte per sample at 8, two little-endian above).
    pub depth: u8,
    pub siting: ChromaSiting,
    pub coefficients: YuvCoefficients,
    /// Clip R'G'B' to [0, 1]; false: extended past it (floats only).
    pub clip: bool,
    /// Per luma row, the chroma rows it interpolates between: progressive frames,
    /// then frames whose chroma is stored per field (`height` each; empty for
    /// luma-only frames).
    pub up_taps: [Vec<UpTap>; 2],
    /// Per chroma row, its luma rows and weights: progressive, then per field
    /// (`chroma_height` each).
    pub down_taps: [Vec<DownTap>; 2],
}

impl PlaneLayout {
    /// Bytes per sample.
    pub fn sample_bytes(&self) -> u32 {
        if self.depth > 8 {
            2
        } else {
            1
        }
    }

    /// Bytes of one frame's planes (Y, Cb, Cr).
    pub fn frame_bytes(&self) -> u64 {
        let luma = u64::from(self.width) * u64::from(self.height);
        let chroma = u64::from(self.chroma_width) * u64::from(self.chroma_height);
        (luma + 2 * chroma) * u64::from(self.sample_bytes())
    }

    fn has_chroma(&self) -> bool {
        self.chroma_width > 0 && self.chroma_height > 0
    }

    /// The uniform block for frames with chroma per field (`fields`) or not, the RGB
    /// side's texels in `format` (`rgb` of the shaders).
    pub(super) fn params(&self, fields: bool, rgb: u32) -> Params {
        let k = self.coefficients;
        Params {
            width: self.width,
            height: self.height,
            chroma_width: if self.has_chroma() {
                self.chroma_width
            } else {
                0
            },
            chroma_height: if self.has_chroma() {
                self.chroma_height
            } else {
                0
            },
            bytes: self.sample_bytes(),
            h_siting: match self.siting {
                ChromaSiting::Full => 0,
                ChromaSiting::Between => 1,
                ChromaSiting::CoSited => 2,
            },
            fields: u32::from(fields && self.has_chroma()),
            clip: u32::from(self.clip),
            rgb,
            row_words: 0,
            words: 0,
            groups_x: 0,
            y_off: k.y_off,
            y_scale: k.y_scale,
            c_mid: k.c_mid,
            c_scale: k.c_scale,
            max_code: k.max,
            kr: k.kr,
            kg: k.kg,
            kb: k.kb,
            rv: k.rv,
            gu: k.gu,
            gv: k.gv,
            bu: k.bu,
        }
    }

    /// The up taps as the shader's table (16 bytes a row); one zero row when empty.
    pub(super) fn up_table(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for t in self.up_taps.iter().flatten() {
            for w in [t.i0, t.i1, t.w.to_bits(), 0] {
                out.extend_from_slice(&w.to_le_bytes());
            }
        }
        if out.is_empty() {
            out.resize(16, 0);
        }
        out
    }

    /// The down taps as the shader's table (32 bytes a row); one zero row when empty.
    pub(super) fn down_table(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for t in self.down_taps.iter().flatten() {
            let words = [
                t[0].0,
                t[1].0,
                t[2].0,
                0,
                t[0].1.to_bits(),
                t[1].1.to_bits(),
                t[2].1.to_bits(),
                0,
            ];
            for w in words {
                out.extend_from_slice(&w.to_le_bytes());
            }
        }
        if out.is_empty() {
            out.resize(32, 0);
        }
        out
    }

    /// Check the tables' lengths against the sizes.
    pub(super) fn check(&self) -> Result<(), String> {
        if !(8..=16).contains(&self.depth) {
            return Err(format!("{} bits per sample", self.depth));
        }
        if self.width == 0 || self.height == 0 {
            return Err("an empty frame".into());
        }
        if !self.has_chroma() {
            return Ok(());
        }
        let (h, ch) = (self.height as usize, self.chroma_height as usize);
        let up = self.up_taps.iter().all(|t| t.len() == h);
        let down = self.down_taps.iter().all(|t| t.len() == ch);
        let inside = self
            .up_taps
            .iter()
            .flatten()
            .all(|t| t.i0.max(t.i1) < ch as u32)
            && self
                .down_taps
                .iter()
                .flatten()
                .all(|t| t.iter().all(|&(r, _)| r < h as u32));
        if !(up && down && inside) {
            return Err("chroma taps that do not fit the frame".into());
        }
        Ok(())
    }
}

/// The RGB side of a conversion: the shaders' `rgb` (0: 8-bit codes, 1: rgba16f,
/// 2: rgba32f) and bytes per texel; `None` for other formats.
pub(super) fn rgb_mode(format: Format) -> Option<(u32, u32)> {
    match format {
        Format::Rgba8 | Format::Rgba8Srgb => Some((0, 4)),
        Format::Rgba16f => Some((1, 8)),
        Format::Rgba32f => Some((2, 16)),
        _ => None,
    }
}

/// `shaders/yuv/yuv_params.wgsl`'s `Params`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct Params {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) chroma_width: u32,
    pub(super) chroma_height: u32,
    pub(super) bytes: u32,
    pub(super) h_siting: u32,
    pub(super) fields: u32,
    pub(super) clip: u32,
    pub(super) rgb: u32,
    pub(super) row_words: u32,
    pub(super) words: u32,
    pub(super) groups_x: u32,
    pub(super) y_off: f32,
    pub(super) y_scale: f32,
    pub(super) c_mid: f32,
    pub(super) c_scale: f32,
    pub(super) max_code: f32,
    pub(super) kr: f32,
    pub(super) kg: f32,
    pub(super) kb: f32,
    pub(super) rv: f32,
    pub(super) gu: f32,
    pub(super) gv: f32,
    pub(super) bu: f32,
}
