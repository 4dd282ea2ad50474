//! y4m and video frames converted on the GPU: a stream's header and conversion as
//! the [`PlaneLayout`] of `gpu::yuv`, built from the CPU conversion's own
//! coefficients and chroma taps (`io::yuv`), and when the GPU path serves a
//! stream ([`PlaneConversion`]).

use crate::gpu::yuv::{ChromaSiting, PlaneLayout, UpTap, YuvCoefficients};
use crate::io::y4m::{Siting, Y4mHeader, YuvConversion};
use crate::io::yuv::{vertical_down_taps, vertical_up_taps, Coeffs};
use std::sync::{Arc, Mutex};

/// Where the Y'CbCr frames of y4m and video streams are converted to and from RGB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlaneConversion {
    /// On the GPU, except on CPU adapters (lavapipe, llvmpipe, WARP), where the
    /// vectorised CPU conversion costs less than the shader's.
    #[default]
    Auto,
    /// Always on the CPU (`io::yuv`).
    Cpu,
    /// On the GPU wherever it can serve the stream.
    Gpu,
}

impl PlaneConversion {
    /// Whether to try the GPU on an adapter of `device_type`.
    pub fn wants_gpu(self, device_type: wgpu::DeviceType) -> bool {
        match self {
            PlaneConversion::Auto => device_type != wgpu::DeviceType::Cpu,
            PlaneConversion::Cpu => false,
            PlaneConversion::Gpu => true,
        }
    }
}

impl std::str::FromStr for PlaneConversion {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(PlaneConversion::Auto),
            "cpu" => Ok(PlaneConversion::Cpu),
            "gpu" => Ok(PlaneConversion::Gpu),
            _ => Err(format!("`{s}` is not one of auto, cpu, gpu")),
        }
    }
}

/// Whether a run's sources send Y'CbCr planes to the GPU: decided once the device
/// exists ([`PlaneRoute::set`]). A source does not wait for it: the frames it reads
/// before ([`PlaneRoute::decided`] is `None`) are converted on the CPU, as the
/// device is being made.
#[derive(Clone, Default)]
pub struct PlaneRoute(Arc<Mutex<Option<bool>>>);

impl PlaneRoute {
    /// A route decided already.
    pub fn known(to_gpu: bool) -> Self {
        let r = PlaneRoute::default();
        r.set(to_gpu);
        r
    }

    /// Decide (once the device exists, or failed: then `false`).
    pub fn set(&self, to_gpu: bool) {
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = Some(to_gpu);
    }

    /// Whether planes go to the GPU, once decided.
    pub fn decided(&self) -> Option<bool> {
        *self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Why a stream's frames cannot be converted on the GPU: the shaders convert
/// sRGB / BT.709 R'G'B' (the other signals, PQ, HLG, BT.1886, linear and other
/// primaries, stay with the CPU conversion of `io::yuv`).
pub fn gpu_refusal(conv: &YuvConversion) -> Option<String> {
    (!conv.color.is_srgb()).then(|| {
        format!(
            "the {} / {} signal is converted on the CPU",
            conv.color.transfer.name(),
            conv.color.primaries.name()
        )
    })
}

/// The layout of `header`'s frames converted with `conv` (the CPU conversion's
/// coefficients and vertical chroma taps, progressive and per field).
pub fn plane_layout(header: &Y4mHeader, conv: &YuvConversion) -> PlaneLayout {
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let (h, vsiting) = (header.height as usize, chroma.vertical_siting());
    let k = Coeffs::new(conv, header.depth);
    let up = |fields| {
        vertical_up_taps(h, ch, vsiting, fields)
            .into_iter()
            .map(|t| UpTap {
                i0: t.i0,
                i1: t.i1,
                w: t.w,
            })
            .collect()
    };
    let has_chroma = chroma.has_chroma();
    PlaneLayout {
        width: header.width,
        height: header.height,
        chroma_width: cw as u32,
        chroma_height: ch as u32,
        depth: header.depth,
        siting: match chroma.horizontal_siting() {
            Siting::Full => ChromaSiting::Full,
            Siting::Between => ChromaSiting::Between,
            Siting::CoSited => ChromaSiting::CoSited,
        },
        coefficients: YuvCoefficients {
            y_off: k.y_off,
            y_scale: k.y_scale,
            c_mid: k.c_mid,
            c_scale: k.c_scale,
            max: k.max,
            kr: k.kr,
            kg: k.kg,
            kb: k.kb,
            rv: k.rv,
            gu: k.gu,
            gv: k.gv,
            bu: k.bu,
        },
        clip: conv.clip,
        up_taps: if has_chroma {
            [up(false), up(true)]
        } else {
            [Vec::new(), Vec::new()]
        },
        down_taps: if has_chroma {
            [false, true].map(|f| vertical_down_taps(h, ch, vsiting, f))
        } else {
            [Vec::new(), Vec::new()]
        },
    }
}
