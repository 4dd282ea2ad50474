//! Colour science of video signals, from the published formulas: the transfer
//! functions ([`transfer`]: PQ, HLG, BT.1886, sRGB, linear) and the RGB primaries
//! ([`primaries`]: BT.709, BT.2020, Display P3) with the matrices between them.
//!
//! The engine's **working space** is linear light with BT.709 primaries, on an
//! absolute scale: linear 1.0 = [`REFERENCE_WHITE`] cd/m² (the HDR reference white
//! of ITU-R BT.2408, as libplacebo and Blender use). A PQ signal of 203 cd/m²
//! decodes to 1.0, one of 1,000 cd/m² to 4.93; an SDR signal's peak (code 1.0)
//! decodes to 1.0. The WGSL twin of these functions is `shaders/lib/transfer.wgsl`.

pub mod primaries;
pub mod transfer;

pub use primaries::{convert_matrix, Matrix3, Primaries};
pub use transfer::Transfer;

/// cd/m² of linear 1.0 in the working space (ITU-R BT.2408 HDR reference white).
pub const REFERENCE_WHITE: f32 = 203.0;

/// The display peak the HLG OOTF assumes unless told otherwise (cd/m²): BT.2100's
/// reference display, where the system gamma is 1.2.
pub const HLG_DEFAULT_PEAK: f32 = 1000.0;

/// What the pixels of a signal are: its transfer and primaries, and for HLG the
/// display peak its OOTF renders for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignalColor {
    pub transfer: Transfer,
    pub primaries: Primaries,
    /// cd/m² of the display the HLG OOTF renders for (ignored by other transfers).
    pub hlg_peak: f32,
}

impl Default for SignalColor {
    /// sRGB transfer, BT.709 primaries: what untagged images and video are taken for.
    fn default() -> Self {
        SignalColor {
            transfer: Transfer::Srgb,
            primaries: Primaries::Bt709,
            hlg_peak: HLG_DEFAULT_PEAK,
        }
    }
}

impl SignalColor {
    /// HDR10: PQ, BT.2020.
    pub const HDR10: SignalColor = SignalColor {
        transfer: Transfer::Pq,
        primaries: Primaries::Bt2020,
        hlg_peak: HLG_DEFAULT_PEAK,
    };
    /// HLG, BT.2020, for a 1,000 cd/m² display.
    pub const HLG: SignalColor = SignalColor {
        transfer: Transfer::Hlg,
        primaries: Primaries::Bt2020,
        hlg_peak: HLG_DEFAULT_PEAK,
    };
    /// SDR video: BT.709 primaries, the BT.1886 display curve.
    pub const SDR: SignalColor = SignalColor {
        transfer: Transfer::Bt1886,
        primaries: Primaries::Bt709,
        hlg_peak: HLG_DEFAULT_PEAK,
    };

    /// Whether this is the sRGB / BT.709 combination images have always been read
    /// with (the fast paths apply).
    pub fn is_srgb(&self) -> bool {
        self.transfer == Transfer::Srgb && self.primaries == Primaries::Bt709
    }

    /// Signal R'G'B' (each 0..1 over the code range) to linear working-space RGB.
    pub fn decode(&self, rgb: [f32; 3], to_working: &Matrix3) -> [f32; 3] {
        let lin = self.transfer.decode_rgb(rgb, self.primaries, self.hlg_peak);
        to_working.apply(lin)
    }

    /// Linear working-space RGB to signal R'G'B'.
    pub fn encode(&self, rgb: [f32; 3], from_working: &Matrix3) -> [f32; 3] {
        let lin = from_working.apply(rgb);
        self.transfer.encode_rgb(lin, self.primaries, self.hlg_peak)
    }

    /// The matrix from this signal's primaries to the working space's (BT.709).
    pub fn to_working(&self) -> Matrix3 {
        convert_matrix(self.primaries, Primaries::Bt709)
    }

    /// The matrix from the working space's primaries to this signal's.
    pub fn from_working(&self) -> Matrix3 {
        convert_matrix(Primaries::Bt709, self.primaries)
    }
}
