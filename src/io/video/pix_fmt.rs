//! ffmpeg pixel format names: the chroma layout and bit depth they hold, the y4m
//! formats ffmpeg writes for them, and the best format an encoder takes.

use crate::io::y4m::{Chroma, Y4mHeader};

/// Chroma subsampling of a pixel format, as far as fxgraph's y4m layouts go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Layout {
    /// 4:2:0 (and coarser: 4:1:0, 4:1:1 and 4:4:0 are read as 4:4:4).
    Yuv420,
    Yuv422,
    /// 4:4:4, and every RGB format.
    Yuv444,
    /// Luma (grey) only.
    Mono,
}

impl Layout {
    /// The y4m layout (4:2:0 as `C420jpeg` at 8 bits, `C420pN` above).
    pub fn chroma(self, depth: u8) -> Chroma {
        match self {
            Layout::Yuv420 if depth > 8 => Chroma::C420,
            Layout::Yuv420 => Chroma::C420Jpeg,
            Layout::Yuv422 => Chroma::C422,
            Layout::Yuv444 => Chroma::C444,
            Layout::Mono => Chroma::Mono,
        }
    }

    /// The layout of a y4m stream.
    pub fn of_chroma(c: Chroma) -> Layout {
        match c {
            Chroma::C422 => Layout::Yuv422,
            Chroma::C444 => Layout::Yuv444,
            Chroma::Mono => Layout::Mono,
            _ => Layout::Yuv420,
        }
    }
}

/// The layout and the bits per sample of an ffmpeg pixel format name
/// (`yuv420p10le` → 4:2:0, 10; `nv12` → 4:2:0, 8; `rgb48le` → 4:4:4, 16). Unknown
/// names give 4:4:4 at the depth of their digits, or 8.
pub fn parse(name: &str) -> (Layout, u8) {
    let n = name.trim_end_matches("le").trim_end_matches("be");
    let layout = if n.starts_with("gray") || n.starts_with("ya8") || n.starts_with("ya16") {
        Layout::Mono
    } else if [
        "yuv420", "yuvj420", "yuva420", "nv12", "nv21", "p010", "p012", "p016",
    ]
    .iter()
    .any(|p| n.starts_with(p))
    {
        Layout::Yuv420
    } else if [
        "yuv422", "yuvj422", "yuva422", "nv16", "nv20", "yuyv422", "uyvy422", "yvyu422", "y210",
        "y212", "p210", "p212", "p216",
    ]
    .iter()
    .any(|p| n.starts_with(p))
    {
        Layout::Yuv422
    } else {
        Layout::Yuv444
    };
    let depth = match n {
        _ if n.starts_with("p0") || n.starts_with("p2") || n.starts_with("p4") => {
            digits_after(n, 2).unwrap_or(10)
        }
        _ if n.starts_with("y21") => digits_after(n, 2).unwrap_or(10),
        _ if n.starts_with("rgb48") || n.starts_with("bgr48") => 16,
        _ if n.starts_with("rgba64") || n.starts_with("bgra64") => 16,
        _ if n.starts_with("gbrpf") || n.starts_with("gbrapf") || n.starts_with("grayf") => 16,
        _ if n.starts_with("ya16") => 16,
        _ if n.starts_with("nv20") => 10,
        _ => trailing_depth(n).unwrap_or(8),
    };
    (layout, depth.clamp(8, 16))
}

/// The digits of `n` from byte `at` (`p010` at 2 → 10).
fn digits_after(n: &str, at: usize) -> Option<u8> {
    let d: String = n
        .get(at..)?
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect();
    d.parse().ok().filter(|&v| v > 0)
}

/// The depth digits after the last `p` of planar names (`yuv420p10` → 10,
/// `gbrap12` → 12, `gray10` → 10); `None` for 8-bit names (`yuv420p`).
fn trailing_depth(n: &str) -> Option<u8> {
    let body = n
        .strip_prefix("gray")
        .or_else(|| n.rsplit_once('p').map(|(_, d)| d))?;
    if body.is_empty() || !body.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    body.parse().ok()
}

/// The depth a y4m stream takes for `layout` at (at least) `depth` bits: the
/// supported one equal or next above (14 → 16 for mono), at most 16.
pub fn y4m_depth(layout: Layout, depth: u8) -> u8 {
    if depth <= 8 {
        return 8;
    }
    let list: &[u8] = if layout == Layout::Mono {
        &Y4mHeader::MONO_DEPTHS
    } else {
        &Y4mHeader::DEPTHS
    };
    list.iter().copied().find(|&d| d >= depth).unwrap_or(16)
}

/// The ffmpeg name of the planar little-endian format of a layout and depth
/// (`yuv420p`, `yuv420p10le`, `gray16le`).
pub fn name(layout: Layout, depth: u8) -> String {
    let base = match layout {
        Layout::Yuv420 => "yuv420p",
        Layout::Yuv422 => "yuv422p",
        Layout::Yuv444 => "yuv444p",
        Layout::Mono => "gray",
    };
    if depth <= 8 {
        base.to_string()
    } else {
        format!("{base}{depth}le")
    }
}

/// The format an encoder that takes `supported` (its list, in ffmpeg's order) should
/// be given for frames of `layout` at `depth` bits: the planar YUV one of that layout
/// whose depth is the smallest at least `depth` (else the deepest); else, by layout
/// (4:2:0, 4:2:2, 4:4:4), the same rule; else the encoder's first format. `None`
/// when the encoder lists none (ffmpeg then chooses).
pub fn choose(supported: &[String], layout: Layout, depth: u8) -> Option<String> {
    let planar = |n: &str| (n.starts_with("yuv4") || n.starts_with("gray")) && !n.ends_with("be");
    let candidates: Vec<(&String, Layout, u8)> = supported
        .iter()
        .filter(|n| planar(n))
        .map(|n| {
            let (l, d) = parse(n);
            (n, l, d)
        })
        .collect();
    let best_of = |l: Layout| -> Option<String> {
        let of: Vec<_> = candidates.iter().filter(|c| c.1 == l).collect();
        of.iter()
            .filter(|c| c.2 >= depth)
            .min_by_key(|c| c.2)
            .or_else(|| of.iter().max_by_key(|c| c.2))
            .map(|c| c.0.clone())
    };
    let order = match layout {
        Layout::Mono => [Layout::Mono, Layout::Yuv420, Layout::Yuv422, Layout::Yuv444],
        l => [l, Layout::Yuv420, Layout::Yuv422, Layout::Yuv444],
    };
    order
        .into_iter()
        .find_map(best_of)
        .or_else(|| supported.first().cloned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_give_layout_and_depth() {
        assert_eq!(parse("yuv420p"), (Layout::Yuv420, 8));
        assert_eq!(parse("yuvj420p"), (Layout::Yuv420, 8));
        assert_eq!(parse("yuv420p10le"), (Layout::Yuv420, 10));
        assert_eq!(parse("yuv422p12be"), (Layout::Yuv422, 12));
        assert_eq!(parse("yuv444p16le"), (Layout::Yuv444, 16));
        assert_eq!(parse("nv12"), (Layout::Yuv420, 8));
        assert_eq!(parse("p010le"), (Layout::Yuv420, 10));
        assert_eq!(parse("gray"), (Layout::Mono, 8));
        assert_eq!(parse("gray10le"), (Layout::Mono, 10));
        assert_eq!(parse("rgb24"), (Layout::Yuv444, 8));
        assert_eq!(parse("rgb48le"), (Layout::Yuv444, 16));
        assert_eq!(parse("gbrp10le"), (Layout::Yuv444, 10));
        assert_eq!(parse("yuva444p12le"), (Layout::Yuv444, 12));
        assert_eq!(parse("yuyv422"), (Layout::Yuv422, 8));
    }

    #[test]
    fn encoder_formats_are_chosen_by_layout_then_depth() {
        let x264: Vec<String> = "yuv420p yuvj420p yuv422p yuvj422p yuv444p yuvj444p nv12 nv16 nv21 yuv420p10le yuv422p10le yuv444p10le nv20le gray gray10le"
            .split(' ')
            .map(String::from)
            .collect();
        assert_eq!(choose(&x264, Layout::Yuv420, 8).as_deref(), Some("yuv420p"));
        assert_eq!(
            choose(&x264, Layout::Yuv420, 10).as_deref(),
            Some("yuv420p10le")
        );
        assert_eq!(
            choose(&x264, Layout::Yuv420, 12).as_deref(),
            Some("yuv420p10le")
        );
        assert_eq!(
            choose(&x264, Layout::Yuv444, 9).as_deref(),
            Some("yuv444p10le")
        );
        assert_eq!(choose(&x264, Layout::Mono, 16).as_deref(), Some("gray10le"));
        let prores: Vec<String> = ["yuv422p10le", "yuv444p10le", "yuva444p10le"]
            .map(String::from)
            .to_vec();
        assert_eq!(
            choose(&prores, Layout::Yuv420, 8).as_deref(),
            Some("yuv422p10le")
        );
        assert_eq!(choose(&[], Layout::Yuv420, 8), None);
        assert_eq!(y4m_depth(Layout::Yuv420, 11), 12);
        assert_eq!(y4m_depth(Layout::Mono, 14), 16);
        assert_eq!(name(Layout::Yuv422, 10), "yuv422p10le");
    }
}
