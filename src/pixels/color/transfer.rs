//! Transfer functions, from their published formulas (evaluated in `f32`):
//!
//! - PQ: SMPTE ST 2084 (= ITU-R BT.2100 PQ), absolute: signal ↔ 0..10,000 cd/m².
//! - HLG: ITU-R BT.2100 (= ARIB STD-B67): the OETF and its inverse, and the OOTF
//!   for a display of peak `Lw` (black 0): `Fd = Lw · Ys^(γ−1) · E` with
//!   `γ = 1.2 + 0.42 log10(Lw / 1000)` and `Ys` the scene luminance of `E`.
//! - BT.1886: the reference display EOTF of SDR video (BT.709, BT.601, BT.2020
//!   SDR), with a black level of 0: `L = V^2.4`.
//! - sRGB: IEC 61966-2-1 ([`crate::pixels::srgb`]).
//! - Linear.
//!
//! [`Transfer::decode_rgb`] and [`Transfer::encode_rgb`] work on the absolute scale of
//! the working space (linear 1.0 = [`super::REFERENCE_WHITE`] cd/m² for PQ and HLG;
//! the SDR curves map code 1.0 to 1.0).

use super::primaries::Primaries;
use super::REFERENCE_WHITE;
use crate::pixels::srgb;

/// A transfer function (the curve between signal codes and linear light).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Transfer {
    /// The signal is linear light.
    Linear,
    /// IEC 61966-2-1 sRGB (images; untagged video).
    Srgb,
    /// ITU-R BT.1886 (gamma 2.4, black 0): SDR video tagged BT.709, BT.601 or BT.2020.
    Bt1886,
    /// SMPTE ST 2084 perceptual quantizer (HDR10).
    Pq,
    /// ITU-R BT.2100 hybrid log-gamma.
    Hlg,
}

const PQ_M1: f32 = 2610.0 / 16384.0;
const PQ_M2: f32 = 2523.0 / 4096.0 * 128.0;
const PQ_C1: f32 = 3424.0 / 4096.0;
const PQ_C2: f32 = 2413.0 / 4096.0 * 32.0;
const PQ_C3: f32 = 2392.0 / 4096.0 * 32.0;
/// cd/m² of PQ code 1.0.
pub const PQ_MAX_NITS: f32 = 10_000.0;

const HLG_A: f32 = 0.178_832_77;
const HLG_B: f32 = 1.0 - 4.0 * HLG_A;
const HLG_C: f32 = 0.559_910_7; // 0.5 - a ln(4a)

/// SMPTE ST 2084 EOTF: signal in [0, 1] (clamped; NaN → 0) to cd/m².
pub fn pq_eotf(e: f32) -> f32 {
    #[allow(clippy::manual_clamp)] // `max` first maps NaN to 0
    let e = e.max(0.0).min(1.0);
    let p = e.powf(1.0 / PQ_M2);
    let y = ((p - PQ_C1).max(0.0) / (PQ_C2 - PQ_C3 * p)).powf(1.0 / PQ_M1);
    PQ_MAX_NITS * y
}

/// SMPTE ST 2084 inverse EOTF: cd/m² (clamped to [0, 10000]; NaN → 0) to signal.
pub fn pq_inverse_eotf(nits: f32) -> f32 {
    #[allow(clippy::manual_clamp)]
    let y = (nits / PQ_MAX_NITS).max(0.0).min(1.0);
    let p = y.powf(PQ_M1);
    ((PQ_C1 + PQ_C2 * p) / (1.0 + PQ_C3 * p)).powf(PQ_M2)
}

/// BT.2100 HLG OETF: normalised scene light in [0, 1] (clamped) to signal.
pub fn hlg_oetf(e: f32) -> f32 {
    #[allow(clippy::manual_clamp)]
    let e = e.max(0.0).min(1.0);
    if e <= 1.0 / 12.0 {
        (3.0 * e).sqrt()
    } else {
        HLG_A * (12.0 * e - HLG_B).ln() + HLG_C
    }
}

/// BT.2100 HLG inverse OETF: signal in [0, 1] (clamped) to normalised scene light.
pub fn hlg_inverse_oetf(s: f32) -> f32 {
    #[allow(clippy::manual_clamp)]
    let s = s.max(0.0).min(1.0);
    if s <= 0.5 {
        s * s / 3.0
    } else {
        (((s - HLG_C) / HLG_A).exp() + HLG_B) / 12.0
    }
}

/// The HLG system gamma for a display of `peak` cd/m² (BT.2100 note 5e; 1.2 at
/// 1,000 cd/m²).
pub fn hlg_gamma(peak: f32) -> f32 {
    1.2 + 0.42 * (peak / 1000.0).log10()
}

/// BT.2100 HLG OOTF: scene light `e` (normalised, in primaries whose luminance
/// weights are `w`) to display light in cd/m² on a display of `peak` cd/m².
pub fn hlg_ootf(e: [f32; 3], w: [f32; 3], peak: f32) -> [f32; 3] {
    let ys = (w[0] * e[0] + w[1] * e[1] + w[2] * e[2]).max(0.0);
    let g = hlg_gamma(peak);
    let k = if ys > 0.0 {
        peak * ys.powf(g - 1.0)
    } else {
        0.0
    };
    e.map(|c| k * c)
}

/// The inverse of [`hlg_ootf`]: display light in cd/m² to normalised scene light.
pub fn hlg_inverse_ootf(fd: [f32; 3], w: [f32; 3], peak: f32) -> [f32; 3] {
    let yd = (w[0] * fd[0] + w[1] * fd[1] + w[2] * fd[2]).max(0.0);
    let g = hlg_gamma(peak);
    let k = if yd > 0.0 {
        (yd / peak).powf((1.0 - g) / g) / peak
    } else {
        0.0
    };
    fd.map(|c| k * c)
}

/// BT.1886 EOTF with black 0 (`V^2.4`), extended to negative and super-white
/// values by symmetry and the same power.
pub fn bt1886_eotf(v: f32) -> f32 {
    v.signum() * v.abs().powf(2.4)
}

/// The inverse of [`bt1886_eotf`].
pub fn bt1886_inverse_eotf(l: f32) -> f32 {
    l.signum() * l.abs().powf(1.0 / 2.4)
}

impl Transfer {
    /// The transfer of an ffmpeg `color_transfer` name. `Ok(None)`: unspecified;
    /// `Err(name)`: a transfer fxrun does not decode (`gamma28`, `log100`, ...).
    pub fn from_ffmpeg(name: &str) -> Result<Option<Transfer>, String> {
        Ok(Some(match name {
            "" | "unknown" | "unspecified" | "reserved" => return Ok(None),
            "smpte2084" => Transfer::Pq,
            "arib-std-b67" => Transfer::Hlg,
            "bt709" | "smpte170m" | "bt2020-10" | "bt2020-12" | "bt470m" | "smpte240m" => {
                Transfer::Bt1886
            }
            "iec61966-2-1" | "iec61966_2_1" => Transfer::Srgb,
            "linear" => Transfer::Linear,
            other => return Err(other.to_string()),
        }))
    }

    /// The ffmpeg `color_trc` name written for this transfer.
    pub fn ffmpeg_name(self) -> &'static str {
        match self {
            Transfer::Linear => "linear",
            Transfer::Srgb => "iec61966-2-1",
            Transfer::Bt1886 => "bt709",
            Transfer::Pq => "smpte2084",
            Transfer::Hlg => "arib-std-b67",
        }
    }

    /// The name used in options and messages.
    pub fn name(self) -> &'static str {
        match self {
            Transfer::Linear => "linear",
            Transfer::Srgb => "srgb",
            Transfer::Bt1886 => "bt1886",
            Transfer::Pq => "pq",
            Transfer::Hlg => "hlg",
        }
    }

    /// Whether the signal is HDR (PQ or HLG: scene light above reference white).
    pub fn is_hdr(self) -> bool {
        matches!(self, Transfer::Pq | Transfer::Hlg)
    }

    /// Signal R'G'B' to linear RGB (in the signal's `primaries`) on the working
    /// scale. PQ and HLG signals are clamped to [0, 1] first; the SDR curves are
    /// extended past [0, 1] (sRGB's linear segment below 0, the power above 1).
    /// `hlg_peak`: the display peak of the HLG OOTF (cd/m²).
    pub fn decode_rgb(self, s: [f32; 3], primaries: Primaries, hlg_peak: f32) -> [f32; 3] {
        match self {
            Transfer::Linear => s,
            Transfer::Srgb => s.map(srgb::srgb_to_linear),
            Transfer::Bt1886 => s.map(bt1886_eotf),
            Transfer::Pq => s.map(|v| pq_eotf(v) / REFERENCE_WHITE),
            Transfer::Hlg => {
                let e = s.map(hlg_inverse_oetf);
                hlg_ootf(e, primaries.luminance_weights(), hlg_peak).map(|v| v / REFERENCE_WHITE)
            }
        }
    }

    /// Linear RGB on the working scale (in the signal's `primaries`) to signal
    /// R'G'B'. PQ: clamped to 0..10,000 cd/m² (NaN → 0); HLG: clamped to the
    /// display's 0..`hlg_peak`; the SDR curves are not clamped.
    pub fn encode_rgb(self, l: [f32; 3], primaries: Primaries, hlg_peak: f32) -> [f32; 3] {
        match self {
            Transfer::Linear => l,
            Transfer::Srgb => l.map(srgb::linear_to_srgb),
            Transfer::Bt1886 => l.map(bt1886_inverse_eotf),
            Transfer::Pq => l.map(|v| pq_inverse_eotf(v * REFERENCE_WHITE)),
            Transfer::Hlg => {
                #[allow(clippy::manual_clamp)]
                let fd = l.map(|v| (v * REFERENCE_WHITE).max(0.0).min(hlg_peak));
                let e = hlg_inverse_ootf(fd, primaries.luminance_weights(), hlg_peak);
                e.map(hlg_oetf)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f32, b: f32) -> f32 {
        (a - b).abs() / b.abs().max(1e-6)
    }

    #[test]
    fn pq_matches_st2084_values() {
        // SMPTE ST 2084 / BT.2408 anchors: 0 → 0, 1 → 10,000 cd/m²; 100 cd/m²
        // at 0.508078, 203 (HDR reference white, BT.2408's 58 %) at 0.580689,
        // 1,000 at 0.751827 (the formula in f64).
        assert_eq!(pq_eotf(0.0), 0.0);
        assert!(rel(pq_eotf(1.0), 10_000.0) < 1e-5);
        // f32 tolerances: the m2 = 78.8 power of the inverse multiplies the base's
        // rounding to 1e-5 of a code; c2 - c3 p cancels to 0.29 at 203 cd/m² in
        // the EOTF: 5e-5 relative. Both far below a 10-bit step (~1e-3).
        for (nits, code) in [(100.0, 0.508_078), (203.0, 0.580_689), (1000.0, 0.751_827)] {
            assert!((pq_inverse_eotf(nits) - code).abs() < 1e-5, "{nits}");
            assert!(rel(pq_eotf(code), nits) < 5e-5, "{nits}");
        }
        // The working scale: 203 cd/m² is 1.0, 1,000 cd/m² is 4.93.
        let one = Transfer::Pq.decode_rgb([0.580_689; 3], Primaries::Bt2020, 1000.0);
        assert!(rel(one[0], 1.0) < 5e-5);
        let k = Transfer::Pq.decode_rgb([0.751_827; 3], Primaries::Bt2020, 1000.0);
        assert!(rel(k[0], 1000.0 / 203.0) < 5e-5 && (k[0] - 4.93).abs() < 0.005);
        // Round trip over the whole range, within 1/50 of a 10-bit code.
        for i in 0..=1023 {
            let e = i as f32 / 1023.0;
            assert!((pq_inverse_eotf(pq_eotf(e)) - e).abs() < 2e-5, "{e}");
        }
        assert_eq!(pq_inverse_eotf(f32::NAN), pq_inverse_eotf(0.0));
        assert_eq!(pq_inverse_eotf(f32::INFINITY), 1.0);
    }

    #[test]
    fn hlg_matches_bt2100() {
        // OETF: 1/12 → 0.5, 1 → 1 (a ln(12 - b) + c = 1.0000000); continuous.
        assert!((hlg_oetf(1.0 / 12.0) - 0.5).abs() < 1e-6);
        assert!((hlg_oetf(1.0) - 1.0).abs() < 1e-6);
        for i in 0..=1000 {
            let s = i as f32 / 1000.0;
            assert!((hlg_oetf(hlg_inverse_oetf(s)) - s).abs() < 2e-6, "{s}");
        }
        // BT.2408: HLG 75 % grey is the reference white, 203 cd/m² on a 1,000 cd/m²
        // display (system gamma 1.2): working 1.0 within BT.2408's rounding.
        assert!((hlg_gamma(1000.0) - 1.2).abs() < 1e-6);
        let w = Transfer::Hlg.decode_rgb([0.75; 3], Primaries::Bt2020, 1000.0);
        assert!(rel(w[0], 1.0) < 0.005, "{w:?}");
        // Peak white is the display's peak.
        let p = Transfer::Hlg.decode_rgb([1.0; 3], Primaries::Bt2020, 1000.0);
        assert!(rel(p[0] * REFERENCE_WHITE, 1000.0) < 1e-5);
        // OOTF and its inverse, on a saturated colour, at another display peak.
        let c = [0.9, 0.3, 0.05];
        for peak in [400.0, 1000.0, 2000.0] {
            let l = Transfer::Hlg.decode_rgb(c, Primaries::Bt2020, peak);
            let back = Transfer::Hlg.encode_rgb(l, Primaries::Bt2020, peak);
            for (a, b) in back.iter().zip(c) {
                assert!((a - b).abs() < 1e-5, "{peak}: {back:?}");
            }
        }
    }

    #[test]
    fn sdr_curves() {
        assert!((bt1886_eotf(0.5) - 0.5f32.powf(2.4)).abs() < 1e-7);
        assert!((bt1886_inverse_eotf(bt1886_eotf(0.3)) - 0.3).abs() < 1e-6);
        assert_eq!(bt1886_eotf(-0.5), -bt1886_eotf(0.5));
        let s = Transfer::Srgb.decode_rgb([0.5; 3], Primaries::Bt709, 1000.0);
        assert!((s[0] - 0.214_041_14).abs() < 1e-6);
        assert_eq!(Transfer::from_ffmpeg("smpte2084"), Ok(Some(Transfer::Pq)));
        assert_eq!(
            Transfer::from_ffmpeg("arib-std-b67"),
            Ok(Some(Transfer::Hlg))
        );
        assert_eq!(Transfer::from_ffmpeg("unknown"), Ok(None));
        assert_eq!(Transfer::from_ffmpeg("log100"), Err("log100".into()));
    }
}
