//! The colour options of streams: `--input-color` (what a stream's frames are, for
//! y4m streams, which carry no colour tags, or to override a video's tags) and
//! `--output-color` (what an output stream is written as).

use crate::io::yuv::{Matrix, Range, YuvConversion};
use crate::pixels::color::{Primaries, SignalColor, Transfer};

/// `--input-color transfer=pq,primaries=bt2020,matrix=bt2020,range=limited,peak=1000`:
/// each key optional.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ColorOverride {
    pub transfer: Option<Transfer>,
    pub primaries: Option<Primaries>,
    pub matrix: Option<Matrix>,
    pub range: Option<Range>,
    /// HLG display peak in cd/m².
    pub hlg_peak: Option<f32>,
}

/// The names `--input-color` takes for each key, for messages.
pub const INPUT_COLOR_KEYS: &str = "transfer=pq|hlg|bt1886|srgb|linear, primaries=bt709|bt2020|p3, matrix=bt601|bt709|bt2020, range=limited|full, peak=CD/M2 (HLG display peak, 100 to 10000)";

fn transfer_of(v: &str) -> Option<Transfer> {
    Some(match v {
        "pq" | "smpte2084" | "st2084" => Transfer::Pq,
        "hlg" | "arib-std-b67" => Transfer::Hlg,
        "bt1886" | "bt709" | "gamma24" => Transfer::Bt1886,
        "srgb" | "iec61966-2-1" => Transfer::Srgb,
        "linear" => Transfer::Linear,
        _ => return None,
    })
}

impl std::str::FromStr for ColorOverride {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let mut o = ColorOverride::default();
        for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let (k, v) = item
                .split_once('=')
                .ok_or_else(|| format!("`{item}`: expected KEY=VALUE ({INPUT_COLOR_KEYS})"))?;
            let v = v.trim().to_ascii_lowercase();
            let bad = || format!("`{item}`: unknown value ({INPUT_COLOR_KEYS})");
            match k.trim() {
                "transfer" | "trc" => o.transfer = Some(transfer_of(&v).ok_or_else(bad)?),
                "primaries" => {
                    o.primaries = Some(match v.as_str() {
                        "p3" | "display-p3" => Primaries::DisplayP3,
                        other => Primaries::from_ffmpeg(other).ok_or_else(bad)?,
                    })
                }
                "matrix" => {
                    o.matrix = Some(match v.as_str() {
                        "bt601" | "smpte170m" | "bt470bg" => Matrix::Bt601,
                        "bt709" => Matrix::Bt709,
                        "bt2020" | "bt2020nc" => Matrix::Bt2020,
                        _ => return Err(bad()),
                    })
                }
                "range" => {
                    o.range = Some(match v.as_str() {
                        "limited" | "tv" => Range::Limited,
                        "full" | "pc" => Range::Full,
                        _ => return Err(bad()),
                    })
                }
                "peak" => {
                    let p: f32 = v.parse().map_err(|_| bad())?;
                    if !(100.0..=10_000.0).contains(&p) {
                        return Err(format!(
                            "`{item}`: the HLG display peak is 100 to 10000 cd/m²"
                        ));
                    }
                    o.hlg_peak = Some(p);
                }
                other => return Err(format!("`{other}`: unknown key ({INPUT_COLOR_KEYS})")),
            }
        }
        Ok(o)
    }
}

impl ColorOverride {
    /// Apply to a conversion. An HDR transfer given without primaries or matrix
    /// takes BT.2020 for both (HDR10 and HLG are BT.2020).
    pub fn apply(&self, conv: &mut YuvConversion) {
        if let Some(t) = self.transfer {
            conv.color.transfer = t;
            if t.is_hdr() {
                if self.primaries.is_none() {
                    conv.color.primaries = Primaries::Bt2020;
                }
                if self.matrix.is_none() {
                    conv.matrix = Matrix::Bt2020;
                }
            }
        }
        if let Some(p) = self.primaries {
            conv.color.primaries = p;
        }
        if let Some(m) = self.matrix {
            conv.matrix = m;
        }
        if let Some(r) = self.range {
            conv.range = r;
        }
        if let Some(p) = self.hlg_peak {
            conv.color.hlg_peak = p;
        }
    }
}

/// `--output-color`: what an output stream is written as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputColor {
    /// PQ, BT.2020 primaries and matrix, limited range, 10 bits by default.
    Hdr10,
    /// HLG (1,000 cd/m² display), BT.2020, limited range, 10 bits by default.
    Hlg,
    /// BT.709 primaries and matrix, BT.1886 curve, limited range, 8 bits by default.
    Sdr,
}

impl std::str::FromStr for OutputColor {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "hdr10" | "pq" => Ok(OutputColor::Hdr10),
            "hlg" => Ok(OutputColor::Hlg),
            "sdr" => Ok(OutputColor::Sdr),
            other => Err(format!("`{other}`: expected hdr10, hlg or sdr")),
        }
    }
}

impl OutputColor {
    /// The signal, matrix and default depth of this output.
    pub fn conversion(self, base: &YuvConversion) -> (YuvConversion, u8) {
        let (color, matrix, depth) = match self {
            OutputColor::Hdr10 => (SignalColor::HDR10, Matrix::Bt2020, 10),
            OutputColor::Hlg => (SignalColor::HLG, Matrix::Bt2020, 10),
            OutputColor::Sdr => (SignalColor::SDR, Matrix::Bt709, 8),
        };
        let conv = YuvConversion {
            matrix,
            range: Range::Limited,
            color,
            ..*base
        };
        (conv, depth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_color_is_parsed() {
        let o: ColorOverride = "transfer=pq, primaries=bt2020,range=full,peak=1000"
            .parse()
            .unwrap();
        assert_eq!(o.transfer, Some(Transfer::Pq));
        assert_eq!(o.primaries, Some(Primaries::Bt2020));
        assert_eq!(o.range, Some(Range::Full));
        assert_eq!(o.hlg_peak, Some(1000.0));
        assert!("transfer=log"
            .parse::<ColorOverride>()
            .unwrap_err()
            .contains("unknown value"));
        assert!("gamma=2"
            .parse::<ColorOverride>()
            .unwrap_err()
            .contains("unknown key"));
        assert!("peak=50".parse::<ColorOverride>().is_err());
        assert_eq!("HDR10".parse::<OutputColor>(), Ok(OutputColor::Hdr10));
        assert!("hdr".parse::<OutputColor>().is_err());
    }
}
