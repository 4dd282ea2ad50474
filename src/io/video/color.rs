//! The colour of a video file: what its tags say (`color_transfer`,
//! `color_primaries`, `color_space`, bit depth) turned into the
//! [`SignalColor`] its frames are decoded with, with warnings where the tags
//! contradict each other; and the HDR metadata (mastering display, content light
//! level) from ffprobe's side data, written again into HDR outputs.

use super::probe::VideoInfo;
use crate::io::yuv::Matrix;
use crate::pixels::color::{Primaries, SignalColor, Transfer};
use serde::Deserialize;

/// SMPTE ST 2086 mastering display colour volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mastering {
    /// CIE 1931 xy of the red, green and blue primaries.
    pub primaries: [[f64; 2]; 3],
    pub white: [f64; 2],
    /// cd/m².
    pub max_luminance: f64,
    pub min_luminance: f64,
}

/// HDR static metadata of a stream.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HdrMetadata {
    pub mastering: Option<Mastering>,
    /// CTA-861.3 MaxCLL and MaxFALL (cd/m²).
    pub max_cll: Option<u32>,
    pub max_fall: Option<u32>,
}

impl HdrMetadata {
    /// Whether there is any.
    pub fn is_empty(&self) -> bool {
        self.mastering.is_none() && self.max_cll.is_none() && self.max_fall.is_none()
    }

    /// The content's peak in cd/m², as players take it: MaxCLL when given, else the
    /// mastering display's peak.
    pub fn peak_nits(&self) -> Option<f32> {
        self.max_cll
            .filter(|&c| c > 0)
            .map(|c| c as f32)
            .or_else(|| {
                self.mastering
                    .map(|m| m.max_luminance as f32)
                    .filter(|&m| m > 0.0)
            })
    }

    /// The x264 / x265 parameters carrying it (`mastering-display=...`/`master-display`,
    /// `cll`/`max-cll`), in their units (xy in 1/50000, luminance in 1/10000 cd/m²).
    pub fn encoder_params(&self, codec: &str) -> Vec<String> {
        let (md, cll) = match codec {
            "libx265" => ("master-display", "max-cll"),
            "libx264" => ("mastering-display", "cll"),
            _ => return Vec::new(),
        };
        let mut out = Vec::new();
        if let Some(m) = &self.mastering {
            let xy = |p: [f64; 2]| {
                format!(
                    "({},{})",
                    (p[0] * 50000.0).round() as u32,
                    (p[1] * 50000.0).round() as u32
                )
            };
            out.push(format!(
                "{md}=G{}B{}R{}WP{}L({},{})",
                xy(m.primaries[1]),
                xy(m.primaries[2]),
                xy(m.primaries[0]),
                xy(m.white),
                (m.max_luminance * 10000.0).round() as u64,
                (m.min_luminance * 10000.0).round() as u64
            ));
        }
        if self.max_cll.is_some() || self.max_fall.is_some() {
            out.push(format!(
                "{cll}={},{}",
                self.max_cll.unwrap_or(0),
                self.max_fall.unwrap_or(0)
            ));
        }
        out
    }
}

/// One entry of ffprobe's `side_data_list`.
#[derive(Deserialize, Debug, Default)]
pub(crate) struct SideData {
    side_data_type: Option<String>,
    red_x: Option<String>,
    red_y: Option<String>,
    green_x: Option<String>,
    green_y: Option<String>,
    blue_x: Option<String>,
    blue_y: Option<String>,
    white_point_x: Option<String>,
    white_point_y: Option<String>,
    min_luminance: Option<String>,
    max_luminance: Option<String>,
    max_content: Option<u32>,
    max_average: Option<u32>,
}

/// `34000/50000` → 0.68.
fn fraction(s: &Option<String>) -> Option<f64> {
    let s = s.as_deref()?;
    let v = match s.split_once('/') {
        Some((n, d)) => n.trim().parse::<f64>().ok()? / d.trim().parse::<f64>().ok()?,
        None => s.trim().parse().ok()?,
    };
    v.is_finite().then_some(v)
}

/// The HDR metadata in side data entries (a stream's or its first frame's).
pub(crate) fn hdr_metadata(list: &[SideData]) -> HdrMetadata {
    let mut m = HdrMetadata::default();
    for d in list {
        match d.side_data_type.as_deref() {
            Some("Mastering display metadata") => {
                let xy =
                    |x: &Option<String>, y: &Option<String>| Some([fraction(x)?, fraction(y)?]);
                let (Some(r), Some(g), Some(b), Some(w)) = (
                    xy(&d.red_x, &d.red_y),
                    xy(&d.green_x, &d.green_y),
                    xy(&d.blue_x, &d.blue_y),
                    xy(&d.white_point_x, &d.white_point_y),
                ) else {
                    continue;
                };
                m.mastering = Some(Mastering {
                    primaries: [r, g, b],
                    white: w,
                    max_luminance: fraction(&d.max_luminance).unwrap_or(0.0),
                    min_luminance: fraction(&d.min_luminance).unwrap_or(0.0),
                });
            }
            Some("Content light level metadata") => {
                m.max_cll = d.max_content.filter(|&v| v > 0);
                m.max_fall = d.max_average.filter(|&v| v > 0);
            }
            _ => {}
        }
    }
    m
}

/// How a video's frames are decoded, from its tags, and what is doubtful about them.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoColor {
    pub color: SignalColor,
    /// Warnings (tags that contradict each other, an HDR stream of 8 bits, ...).
    pub warnings: Vec<String>,
}

/// The colour of a probed video: PQ and HLG from `color_transfer` (SDR transfers
/// keep the sRGB curve fxrun reads SDR video with), the primaries from
/// `color_primaries` (BT.2020 for PQ / HLG when untagged). Errors: a transfer or
/// primaries fxrun cannot decode (the message says which, and how to override it).
pub fn video_color(info: &VideoInfo) -> Result<VideoColor, String> {
    let mut warnings = Vec::new();
    let trc = info.color_transfer.as_deref().unwrap_or("");
    let transfer = Transfer::from_ffmpeg(trc).map_err(|t| {
        format!(
            "the video's transfer `{t}` is not one fxrun decodes (it reads smpte2084 (PQ), arib-std-b67 (HLG), bt709, smpte170m, bt2020-10/12, iec61966-2-1, linear): say what the frames are with --input-color transfer=...,primaries=..."
        )
    })?;
    let hdr = transfer.is_some_and(Transfer::is_hdr);
    let primaries = match info.color_primaries.as_deref() {
        None => None,
        Some(p) => Some(Primaries::from_ffmpeg(p).ok_or_else(|| {
            format!(
                "the video's primaries `{p}` are not ones fxrun converts (bt709, bt2020, smpte432): say what the frames are with --input-color primaries=..."
            )
        })?),
    };
    let primaries = match (primaries, hdr) {
        (Some(p), _) => p,
        (None, true) => {
            warnings.push(format!(
                "the video is {} without primaries: read as BT.2020",
                trc
            ));
            Primaries::Bt2020
        }
        (None, false) => Primaries::Bt709,
    };
    if hdr {
        if primaries != Primaries::Bt2020 {
            warnings.push(format!(
                "the tags contradict each other: transfer {trc} (HDR) with primaries {} (HDR10 and HLG use BT.2020): decoded as tagged; --input-color overrides",
                primaries.ffmpeg_name()
            ));
        }
        if let Some(m) = info.matrix.filter(|&m| m != Matrix::Bt2020) {
            warnings.push(format!(
                "the tags contradict each other: transfer {trc} (HDR) with the {m:?} matrix (HDR10 and HLG use BT.2020 non-constant luminance): decoded with the tagged matrix"
            ));
        }
        if info.depth < 10 {
            warnings.push(format!(
                "an HDR ({trc}) stream of {} bits: expect banding (HDR video is 10 or 12 bits)",
                info.depth
            ));
        }
    }
    let transfer = match transfer {
        Some(t) if t.is_hdr() || t == Transfer::Linear => t,
        // SDR video keeps the sRGB curve fxrun has always read it with (an effect's
        // linear values; a round trip is exact either way).
        _ => Transfer::Srgb,
    };
    Ok(VideoColor {
        color: SignalColor {
            transfer,
            primaries,
            ..SignalColor::default()
        },
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_data_and_encoder_params() {
        let list: Vec<SideData> = serde_json::from_str(
            r#"[{"side_data_type":"Mastering display metadata","red_x":"34000/50000","red_y":"16000/50000",
                 "green_x":"13250/50000","green_y":"34500/50000","blue_x":"7500/50000","blue_y":"3000/50000",
                 "white_point_x":"15635/50000","white_point_y":"16450/50000","min_luminance":"50/10000",
                 "max_luminance":"10000000/10000"},
                {"side_data_type":"Content light level metadata","max_content":1000,"max_average":400}]"#,
        )
        .unwrap();
        let m = hdr_metadata(&list);
        assert_eq!((m.max_cll, m.max_fall), (Some(1000), Some(400)));
        assert_eq!(m.peak_nits(), Some(1000.0));
        let md = m.mastering.unwrap();
        assert_eq!((md.max_luminance, md.min_luminance), (1000.0, 0.005));
        assert_eq!(
            m.encoder_params("libx265"),
            vec![
                "master-display=G(13250,34500)B(7500,3000)R(34000,16000)WP(15635,16450)L(10000000,50)".to_string(),
                "max-cll=1000,400".to_string()
            ]
        );
    }
}
