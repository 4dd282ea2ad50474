//! The stream header: size, rate, interlacing, aspect, chroma layout, extensions.

use super::*;
use std::fmt;

/// The `I` field: how the frames were scanned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Interlace {
    /// `Ip`.
    Progressive,
    /// `It`: interlaced, top field first.
    TopFieldFirst,
    /// `Ib`: interlaced, bottom field first.
    BottomFieldFirst,
    /// `Im`: mixed; each frame's `FRAME I...` parameter says (ffmpeg refuses such streams).
    Mixed,
    /// `I?`: unknown.
    Unknown,
}

impl Interlace {
    /// The header letter.
    pub fn code(self) -> char {
        match self {
            Interlace::Progressive => 'p',
            Interlace::TopFieldFirst => 't',
            Interlace::BottomFieldFirst => 'b',
            Interlace::Mixed => 'm',
            Interlace::Unknown => '?',
        }
    }

    /// The value of a header letter.
    pub fn from_code(c: char) -> Option<Interlace> {
        Some(match c {
            'p' => Interlace::Progressive,
            't' => Interlace::TopFieldFirst,
            'b' => Interlace::BottomFieldFirst,
            'm' => Interlace::Mixed,
            '?' => Interlace::Unknown,
            _ => return None,
        })
    }

    /// `It` or `Ib`.
    pub fn is_interlaced(self) -> bool {
        matches!(self, Interlace::TopFieldFirst | Interlace::BottomFieldFirst)
    }
}

/// Where chroma samples sit relative to the luma grid along one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Siting {
    /// Not subsampled along this axis.
    Full,
    /// Halfway between two luma samples.
    Between,
    /// On the even luma samples.
    CoSited,
}

/// The `C` field's sample layout; its bit depth is [`Y4mHeader::depth`] (`C420p10` is
/// [`Chroma::C420`] at 10 bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Chroma {
    /// `C420jpeg` (the default): 4:2:0, chroma centred between 2x2 luma samples.
    C420Jpeg,
    /// `C420paldv`: 4:2:0 as in PAL DV (treated as co-sited on even rows and columns).
    C420Paldv,
    /// `C420mpeg2`: 4:2:0, chroma on even columns, between rows.
    C420Mpeg2,
    /// `C420`: 4:2:0 (read by ffmpeg as centred, like `420jpeg`).
    C420,
    /// `C422`: 4:2:2, chroma on even columns.
    C422,
    /// `C444`: no subsampling.
    C444,
    /// `Cmono`: luma only.
    Mono,
}

impl Chroma {
    /// Every layout.
    pub const ALL: [Chroma; 7] = [
        Chroma::C420Jpeg,
        Chroma::C420Paldv,
        Chroma::C420Mpeg2,
        Chroma::C420,
        Chroma::C422,
        Chroma::C444,
        Chroma::Mono,
    ];

    /// The header name (without the `C`).
    pub fn tag(self) -> &'static str {
        match self {
            Chroma::C420Jpeg => "420jpeg",
            Chroma::C420Paldv => "420paldv",
            Chroma::C420Mpeg2 => "420mpeg2",
            Chroma::C420 => "420",
            Chroma::C422 => "422",
            Chroma::C444 => "444",
            Chroma::Mono => "mono",
        }
    }

    /// The layout of a header name (without the `C`).
    pub fn from_tag(tag: &str) -> Option<Chroma> {
        Chroma::ALL.into_iter().find(|c| c.tag() == tag)
    }

    /// Whether there are Cb and Cr planes.
    pub fn has_chroma(self) -> bool {
        self != Chroma::Mono
    }

    /// Whether this is one of the 4:2:0 layouts.
    pub fn is_420(self) -> bool {
        matches!(
            self,
            Chroma::C420Jpeg | Chroma::C420Paldv | Chroma::C420Mpeg2 | Chroma::C420
        )
    }

    /// Horizontal chroma siting.
    pub fn horizontal_siting(self) -> Siting {
        match self {
            Chroma::C420Jpeg | Chroma::C420 => Siting::Between,
            Chroma::C420Mpeg2 | Chroma::C420Paldv | Chroma::C422 => Siting::CoSited,
            Chroma::C444 | Chroma::Mono => Siting::Full,
        }
    }

    /// Vertical chroma siting (of progressive frames).
    pub fn vertical_siting(self) -> Siting {
        match self {
            Chroma::C420Jpeg | Chroma::C420 | Chroma::C420Mpeg2 => Siting::Between,
            Chroma::C420Paldv => Siting::CoSited,
            Chroma::C422 | Chroma::C444 | Chroma::Mono => Siting::Full,
        }
    }

    /// Size of each chroma plane for a `width x height` frame (`(0, 0)` for mono).
    pub fn chroma_size(self, width: u32, height: u32) -> (usize, usize) {
        let (w, h) = (width as usize, height as usize);
        match self {
            Chroma::Mono => (0, 0),
            Chroma::C444 => (w, h),
            Chroma::C422 => (w.div_ceil(2), h),
            _ => (w.div_ceil(2), h.div_ceil(2)),
        }
    }

    /// Bytes of the three planes of an 8-bit frame (samples of the three planes).
    pub fn frame_bytes(self, width: u32, height: u32) -> usize {
        let (cw, ch) = self.chroma_size(width, height);
        width as usize * height as usize + 2 * cw * ch
    }
}

impl fmt::Display for Chroma {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.tag())
    }
}

/// A stream header. [`Y4mHeader::parse`] and [`Y4mHeader::to_line`] are inverse for
/// every field kept (unknown non-`X` fields are dropped).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Y4mHeader {
    pub width: u32,
    pub height: u32,
    /// Frame rate as numerator:denominator; `(0, 0)` when unknown.
    pub fps: (u32, u32),
    pub interlace: Interlace,
    /// Pixel aspect ratio; `(0, 0)` when unknown.
    pub aspect: (u32, u32),
    pub colorspace: Chroma,
    /// Bits per sample: 8 (one byte per sample), or 9 to 16 (two bytes per sample,
    /// little-endian, values 0 to 2^depth - 1), as ffmpeg writes them (`C420p10`,
    /// `Cmono16`, ...; see [`Y4mHeader::DEPTHS`]).
    pub depth: u8,
    /// The `X` fields, without the `X`, in order.
    pub extra: Vec<String>,
}

impl Y4mHeader {
    /// The bit depths above 8 of the layouts with chroma (`C420p9` ... `C444p16`), as
    /// ffmpeg's y4m muxer and demuxer know them.
    pub const DEPTHS: [u8; 5] = [9, 10, 12, 14, 16];
    /// The bit depths above 8 of `Cmono` (`Cmono9` ... `Cmono16`).
    pub const MONO_DEPTHS: [u8; 4] = [9, 10, 12, 16];

    /// A progressive 8-bit header with unknown frame rate and aspect, no extensions.
    pub fn new(width: u32, height: u32, colorspace: Chroma) -> Y4mHeader {
        Y4mHeader {
            width,
            height,
            fps: (0, 0),
            interlace: Interlace::Progressive,
            aspect: (0, 0),
            colorspace,
            depth: 8,
            extra: Vec::new(),
        }
    }

    /// Whether `depth` bits per sample can be written for `colorspace` (8 for every
    /// layout; above 8 only [`Chroma::C420`], [`Chroma::C422`], [`Chroma::C444`] and
    /// [`Chroma::Mono`], at the depths of [`Y4mHeader::DEPTHS`] / [`Y4mHeader::MONO_DEPTHS`]:
    /// ffmpeg has no high-depth form of the other 4:2:0 sitings).
    pub fn depth_supported(colorspace: Chroma, depth: u8) -> bool {
        match (colorspace, depth) {
            (_, 8) => true,
            (Chroma::Mono, d) => Y4mHeader::MONO_DEPTHS.contains(&d),
            (Chroma::C420 | Chroma::C422 | Chroma::C444, d) => Y4mHeader::DEPTHS.contains(&d),
            _ => false,
        }
    }

    /// Change the bit depth, adjusting what depends on it: 4:2:0 above 8 bits is
    /// [`Chroma::C420`] (`C420p10`; chroma centred: `420mpeg2` and `420paldv` siting is
    /// not kept), and [`Chroma::C420Jpeg`] back at 8 bits; the `XYSCSS` extension
    /// (ffmpeg's older name of the layout) is dropped. An error names the depths the
    /// layout takes.
    pub fn set_depth(&mut self, depth: u8) -> Result<(), String> {
        let layout = match self.colorspace {
            c if c.is_420() && depth > 8 => Chroma::C420,
            Chroma::C420 if depth == 8 => Chroma::C420Jpeg,
            c => c,
        };
        if !Y4mHeader::depth_supported(layout, depth) {
            let depths = if layout == Chroma::Mono {
                &Y4mHeader::MONO_DEPTHS[..]
            } else {
                &Y4mHeader::DEPTHS[..]
            };
            let list: Vec<String> = std::iter::once(8)
                .chain(depths.iter().copied())
                .map(|d| d.to_string())
                .collect();
            return Err(format!(
                "{depth} bits per sample cannot be written as y4m C{} (supported: {})",
                layout.tag(),
                list.join(", ")
            ));
        }
        if (layout, depth) != (self.colorspace, self.depth) {
            self.extra.retain(|x| !x.starts_with("YSCSS="));
        }
        self.colorspace = layout;
        self.depth = depth;
        Ok(())
    }

    /// The `C` field's value (without the `C`): the layout's tag at 8 bits, `420p10`,
    /// `444p16`, `mono12`, ... above.
    pub fn colorspace_tag(&self) -> String {
        match (self.colorspace, self.depth) {
            (c, 8) => c.tag().to_string(),
            (Chroma::Mono, d) => format!("mono{d}"),
            (Chroma::C422, d) => format!("422p{d}"),
            (Chroma::C444, d) => format!("444p{d}"),
            (_, d) => format!("420p{d}"),
        }
    }

    /// The layout and depth of a `C` field's value (without the `C`).
    pub fn parse_colorspace(tag: &str) -> Option<(Chroma, u8)> {
        if let Some(c) = Chroma::from_tag(tag) {
            return Some((c, 8));
        }
        let (layout, depth) = if let Some(d) = tag.strip_prefix("mono") {
            (Chroma::Mono, d)
        } else {
            let (l, d) = tag.split_once('p')?;
            let layout = match l {
                "420" => Chroma::C420,
                "422" => Chroma::C422,
                "444" => Chroma::C444,
                _ => return None,
            };
            (layout, d)
        };
        if depth.is_empty() || !depth.bytes().all(|b| b.is_ascii_digit()) || depth.len() > 2 {
            return None;
        }
        let depth: u8 = depth.parse().ok()?;
        (depth > 8 && Y4mHeader::depth_supported(layout, depth)).then_some((layout, depth))
    }

    /// Bytes per sample: 1 at 8 bits, 2 above.
    pub fn sample_bytes(&self) -> usize {
        if self.depth > 8 {
            2
        } else {
            1
        }
    }

    /// The largest sample value, `2^depth - 1`.
    pub fn max_code(&self) -> u32 {
        (1u32 << self.depth) - 1
    }

    /// Parse a header line (with or without the final `\n`). The error message says what
    /// is wrong (without the stream's name).
    pub fn parse(line: &[u8]) -> Result<Y4mHeader, String> {
        let line = line.strip_suffix(b"\n").unwrap_or(line);
        if !line.starts_with(MAGIC) || !matches!(line.get(MAGIC.len()), None | Some(b' ')) {
            return Err(format!(
                "not a YUV4MPEG2 stream (it starts with \"{}\")",
                escape(&line[..line.len().min(16)])
            ));
        }
        let text = std::str::from_utf8(&line[MAGIC.len()..])
            .map_err(|_| "the header line is not text".to_string())?;
        let (mut width, mut height) = (None, None);
        let mut h = Y4mHeader::new(0, 0, Chroma::C420Jpeg);
        for tok in text.split(' ').filter(|t| !t.is_empty()) {
            let mut chars = tok.chars();
            let key = chars.next().unwrap_or(' ');
            let val = chars.as_str();
            match key {
                'W' => width = Some(parse_side(val, "width", tok)?),
                'H' => height = Some(parse_side(val, "height", tok)?),
                'F' => h.fps = parse_ratio(val, "frame rate", tok)?,
                'A' => h.aspect = parse_ratio(val, "pixel aspect ratio", tok)?,
                'I' => {
                    let mut c = val.chars();
                    h.interlace = match (c.next(), c.next()) {
                        (Some(c), None) => Interlace::from_code(c),
                        _ => None,
                    }
                    .ok_or_else(|| {
                        format!("invalid interlacing `{tok}` (expected Ip, It, Ib, Im or I?)")
                    })?;
                }
                'C' => {
                    (h.colorspace, h.depth) = Y4mHeader::parse_colorspace(val).ok_or_else(|| {
                        format!(
                            "unsupported colour space `{tok}` (supported: 8-bit C420jpeg, C420mpeg2, C420paldv, C420, C422, C444, Cmono; 9 to 16 bits C420pN, C422pN, C444pN with N 9, 10, 12, 14 or 16, and CmonoN with N 9, 10, 12 or 16)"
                        )
                    })?;
                }
                'X' => h.extra.push(val.to_string()),
                _ => log::debug!("y4m header: ignoring unknown field `{tok}`"),
            }
        }
        h.width = width.ok_or("missing W (width)")?;
        h.height = height.ok_or("missing H (height)")?;
        Ok(h)
    }

    /// Check the fields a writer relies on: sizes within limits, ratios either both zero
    /// or both non-zero, a depth the layout takes ([`Y4mHeader::depth_supported`]),
    /// extension fields non-empty without spaces or newlines.
    pub fn validate(&self) -> Result<(), String> {
        if !Y4mHeader::depth_supported(self.colorspace, self.depth) {
            return Err(format!(
                "C{} has no {}-bit form (above 8 bits: C420, C422, C444, Cmono)",
                self.colorspace.tag(),
                self.depth
            ));
        }
        for (v, what) in [(self.width, "width"), (self.height, "height")] {
            if v == 0 || v > MAX_SIDE {
                return Err(format!("{what} {v} is out of range (1 to {MAX_SIDE})"));
            }
        }
        for ((n, d), what) in [
            (self.fps, "frame rate"),
            (self.aspect, "pixel aspect ratio"),
        ] {
            if (n == 0) != (d == 0) {
                return Err(format!("invalid {what} {n}:{d}"));
            }
        }
        for x in &self.extra {
            if x.is_empty() || x.contains([' ', '\n', '\r']) {
                return Err(format!("invalid extension field `X{x}`"));
            }
        }
        Ok(())
    }

    /// The header line, `\n` included: `YUV4MPEG2 W H F I A C` then the `X` fields.
    pub fn to_line(&self) -> String {
        let mut s = format!(
            "YUV4MPEG2 W{} H{} F{}:{} I{} A{}:{} C{}",
            self.width,
            self.height,
            self.fps.0,
            self.fps.1,
            self.interlace.code(),
            self.aspect.0,
            self.aspect.1,
            self.colorspace_tag()
        );
        for x in &self.extra {
            s.push_str(" X");
            s.push_str(x);
        }
        s.push('\n');
        s
    }

    /// Bytes of one frame's planes.
    pub fn frame_bytes(&self) -> usize {
        self.colorspace.frame_bytes(self.width, self.height) * self.sample_bytes()
    }

    /// `(luma, each chroma)` plane sizes in bytes.
    pub fn plane_bytes(&self) -> (usize, usize) {
        let (cw, ch) = self.colorspace.chroma_size(self.width, self.height);
        let b = self.sample_bytes();
        (self.width as usize * self.height as usize * b, cw * ch * b)
    }

    /// The range announced by an `XCOLORRANGE=FULL` / `XCOLORRANGE=LIMITED` extension.
    pub fn range_hint(&self) -> Option<Range> {
        self.extra
            .iter()
            .rev()
            .find_map(|x| x.strip_prefix("COLORRANGE="))
            .and_then(|v| match v {
                "FULL" => Some(Range::Full),
                "LIMITED" => Some(Range::Limited),
                _ => None,
            })
    }
}

fn parse_side(val: &str, what: &str, tok: &str) -> Result<u32, String> {
    if val.is_empty() || !val.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("invalid {what} `{tok}`"));
    }
    let v: u64 = val
        .parse()
        .map_err(|_| format!("{what} `{tok}` is out of range (1 to {MAX_SIDE})"))?;
    if v == 0 || v > MAX_SIDE as u64 {
        return Err(format!("{what} {v} is out of range (1 to {MAX_SIDE})"));
    }
    Ok(v as u32)
}

fn parse_ratio(val: &str, what: &str, tok: &str) -> Result<(u32, u32), String> {
    let bad = || format!("invalid {what} `{tok}` (expected n:d)");
    let (n, d) = val.split_once(':').ok_or_else(bad)?;
    let num = |t: &str| -> Result<u32, String> {
        if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        t.parse().map_err(|_| bad())
    };
    let (n, d) = (num(n)?, num(d)?);
    if (n == 0) != (d == 0) {
        return Err(format!(
            "invalid {what} `{tok}` (both parts must be non-zero, or 0:0 for unknown)"
        ));
    }
    Ok((n, d))
}

/// Printable form of raw bytes for messages.
pub(super) fn escape(b: &[u8]) -> String {
    b.iter()
        .flat_map(|&c| std::ascii::escape_default(c))
        .map(char::from)
        .collect()
}
