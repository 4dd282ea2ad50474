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

/// The `C` field: sample layout, all 8 bits per sample.
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

    /// Bytes of the three planes of a frame.
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
    /// The `X` fields, without the `X`, in order.
    pub extra: Vec<String>,
}

impl Y4mHeader {
    /// A progressive header with unknown frame rate and aspect, no extensions.
    pub fn new(width: u32, height: u32, colorspace: Chroma) -> Y4mHeader {
        Y4mHeader {
            width,
            height,
            fps: (0, 0),
            interlace: Interlace::Progressive,
            aspect: (0, 0),
            colorspace,
            extra: Vec::new(),
        }
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
                    h.colorspace = Chroma::from_tag(val).ok_or_else(|| {
                        format!(
                            "unsupported colour space `{tok}` (supported: 8-bit C420jpeg, C420mpeg2, C420paldv, C420, C422, C444, Cmono)"
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
    /// or both non-zero, extension fields non-empty without spaces or newlines.
    pub fn validate(&self) -> Result<(), String> {
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
            self.colorspace.tag()
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
        self.colorspace.frame_bytes(self.width, self.height)
    }

    /// `(luma, each chroma)` plane sizes in bytes.
    pub fn plane_bytes(&self) -> (usize, usize) {
        let (cw, ch) = self.colorspace.chroma_size(self.width, self.height);
        (self.width as usize * self.height as usize, cw * ch)
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
