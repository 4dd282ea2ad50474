//! YUV4MPEG2 (`.y4m`, `ffmpeg -f yuv4mpegpipe`) streams: a reader, a writer, and the
//! conversions between 8-bit Y'CbCr frames and RGBA [`Image`]s.
//!
//! # Format
//!
//! A stream is one header line, `YUV4MPEG2` followed by space-separated fields and `\n`:
//!
//! | field | meaning | here |
//! |---|---|---|
//! | `W<w>` `H<h>` | size (required) | 1 to [`MAX_SIDE`] each |
//! | `F<n>:<d>` | frame rate | [`Y4mHeader::fps`]; `0:0` (also when absent) = unknown |
//! | `I<p\|t\|b\|m\|?>` | progressive, top / bottom field first, mixed (per frame), unknown | [`Interlace`] |
//! | `A<n>:<d>` | pixel aspect ratio | [`Y4mHeader::aspect`]; `0:0` (also when absent) = unknown |
//! | `C<name>` | sample layout | [`Chroma`]; `420jpeg` when absent |
//! | `X<text>` | extensions (`XCOLORRANGE=FULL`, `XYSCSS=420MPEG2`, ...) | [`Y4mHeader::extra`], passed through |
//!
//! Unknown fields are ignored. Each frame is a line `FRAME` (optionally followed by
//! space-separated parameters, kept in [`YuvFrame::params`]) and the planes Y, Cb, Cr
//! (only Y for `Cmono`), 8 bits per sample, rows top to bottom without padding. Chroma
//! planes of 4:2:0 are `ceil(w/2) x ceil(h/2)`, of 4:2:2 `ceil(w/2) x h`.
//!
//! Frame numbers in messages count from 0 (the first frame of the stream is frame 0), and
//! say so: `stdin: y4m frame 12 (0-based): truncated (got 1000 of 622080 bytes)`.
//!
//! Limits: [`MAX_SIDE`] per side, header lines up to [`MAX_HEADER_BYTES`] and frame lines
//! up to [`MAX_FRAME_LINE_BYTES`]. A frame's buffers grow as its bytes arrive (in steps of
//! at most 16 MiB), so a header announcing a huge size allocates nothing a truncated
//! stream does not deliver.
//!
//! # Colour
//!
//! [`YuvConversion`] says how Y'CbCr maps to R'G'B': [`Matrix::Bt601`] or
//! [`Matrix::Bt709`], [`Range::Limited`] (Y 16-235, Cb/Cr 16-240) or [`Range::Full`]
//! (0-255, chroma scaled by 255 as in JPEG). [`YuvConversion::for_header`] picks BT.601 for
//! heights up to 576 and BT.709 above, and limited range unless the header says
//! `XCOLORRANGE=FULL` (ffmpeg writes that extension when it knows the range). The R'G'B'
//! values are treated as sRGB-encoded, the same convention as 8-bit image files, so a
//! y4m → PNG → y4m trip is consistent: [`RgbKind::SrgbU8`] gives the R'G'B' bytes and
//! [`RgbKind::LinearF32`] their sRGB decode to linear light.
//!
//! # Chroma siting
//!
//! Chroma is upsampled bilinearly from the sample positions of the layout and downsampled
//! with the matching filter at those positions:
//!
//! | layout | horizontal | vertical | downsampling |
//! |---|---|---|---|
//! | `420jpeg`, `420` | between luma columns | between luma rows | 2x2 box |
//! | `420mpeg2` | on even luma columns | between luma rows | [1 2 1]/4 across, box down |
//! | `420paldv` | on even luma columns | on even luma rows | [1 2 1]/4 both ways |
//! | `422` | on even luma columns | — | [1 2 1]/4 across |
//! | `444`, `mono` | — | — | — |
//!
//! `420paldv` really has Cr on the top-field lines and Cb on the bottom-field ones; like
//! ffmpeg, it is treated as "top-left" (co-sited on even rows and columns).
//!
//! Interlaced 4:2:0 (`It`/`Ib`, or a `FRAME Ixyz` parameter with `z` = `i` in an `Im`
//! stream) stores each field's chroma in alternate chroma rows: chroma row `2k + f`
//! belongs to field `f` and sits between that field's lines (top field: a quarter of the
//! way, bottom field: three quarters). With [`ChromaFields::Auto`] such frames are
//! resampled within each field (no chroma mixing across fields, which a deinterlacer needs):
//! upsampling interpolates between the field's chroma rows, downsampling weights the two
//! field lines around each chroma row 3:1 (top field) or 1:3 (bottom field). This applies
//! to `420jpeg`, `420mpeg2` and `420` (not `420paldv`). At the picture edges the nearest
//! chroma sample is repeated. ffmpeg's default RGB conversion ignores interlacing (and
//! replicates chroma); its `scale=interl=1` does the same as here (see the tests).
//!
//! # Speed
//!
//! The conversions are branch-free per-row f32 loops over planar rows, which the compiler
//! vectorises, without allocation per pixel (a few row buffers per thread), split over
//! threads by row bands for frames of 65536 pixels or more. The sRGB curve is a fitted
//! polynomial (error below 4e-6, exact linear segment near black). For the GPU pipeline
//! [`RgbKind::SrgbU8`] is the cheaper choice: 8-bit sRGB textures are decoded by the GPU.

use std::fmt;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::sync::OnceLock;

use super::{srgb, FileFormat, Image, IoError, Pixels, SourceInfo};

/// Largest accepted width or height.
pub const MAX_SIDE: u32 = 16384;
/// Longest accepted header line, newline included.
pub const MAX_HEADER_BYTES: usize = 4096;
/// Longest accepted `FRAME` line, newline included.
pub const MAX_FRAME_LINE_BYTES: usize = 1024;
/// ffmpeg's demuxer (up to at least 7.x) reads header lines of at most 96 bytes; the
/// writer logs a warning above that.
const FFMPEG_MAX_HEADER: usize = 96;

const MAGIC: &[u8] = b"YUV4MPEG2";
const FRAME_MAGIC: &[u8] = b"FRAME";
/// Largest step a frame buffer grows by before its data has arrived.
const READ_CHUNK: usize = 16 << 20;

/// Errors of the YUV4MPEG2 reader and writer. Every message starts with the stream's name
/// (`stdin`, a file name); frame numbers count from 0.
#[derive(Debug, thiserror::Error)]
pub enum Y4mError {
    /// The header line is missing, malformed, out of limits or unsupported.
    #[error("{name}: y4m header: {message}")]
    Header { name: String, message: String },
    /// A frame is malformed or truncated (reading), or does not fit the header (writing).
    #[error("{name}: y4m frame {frame} (0-based): {message}")]
    Frame {
        name: String,
        frame: u64,
        message: String,
    },
    /// Reading or writing failed (other than a truncated stream).
    #[error("{name}: {context}: {source}")]
    Io {
        name: String,
        context: String,
        source: io::Error,
    },
}

impl Y4mError {
    /// The stream's name.
    pub fn name(&self) -> &str {
        match self {
            Y4mError::Header { name, .. }
            | Y4mError::Frame { name, .. }
            | Y4mError::Io { name, .. } => name,
        }
    }

    /// The frame (0-based) the error is about, if any.
    pub fn frame(&self) -> Option<u64> {
        match self {
            Y4mError::Frame { frame, .. } => Some(*frame),
            _ => None,
        }
    }
}

impl From<Y4mError> for IoError {
    /// [`Y4mError::Io`] becomes [`IoError::Io`], the others [`IoError::Decode`] (input
    /// rejected), with the stream's name as the path and the same message.
    fn from(e: Y4mError) -> IoError {
        match e {
            Y4mError::Io {
                name,
                context,
                source,
            } => IoError::Io {
                path: name.into(),
                source: io::Error::new(source.kind(), format!("{context}: {source}")),
            },
            Y4mError::Header { name, message } => IoError::Decode {
                path: name.into(),
                message: format!("y4m header: {message}"),
            },
            Y4mError::Frame {
                name,
                frame,
                message,
            } => IoError::Decode {
                path: name.into(),
                message: format!("y4m frame {frame} (0-based): {message}"),
            },
        }
    }
}

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
fn escape(b: &[u8]) -> String {
    b.iter()
        .flat_map(|&c| std::ascii::escape_default(c))
        .map(char::from)
        .collect()
}

/// One frame: the planes, and the `FRAME` line's parameters.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct YuvFrame {
    /// Luma, `width x height`.
    pub y: Vec<u8>,
    /// Cb, [`Chroma::chroma_size`] (empty for mono).
    pub u: Vec<u8>,
    /// Cr, [`Chroma::chroma_size`] (empty for mono).
    pub v: Vec<u8>,
    /// Parameters after `FRAME` (such as `Itpi` in mixed streams), written back as is.
    pub params: Vec<String>,
}

impl YuvFrame {
    /// A black frame for `header` (Y 16 or 0 for `range`, Cb = Cr = 128).
    pub fn black(header: &Y4mHeader, range: Range) -> YuvFrame {
        let (yn, cn) = header.plane_bytes();
        YuvFrame {
            y: vec![if range == Range::Limited { 16 } else { 0 }; yn],
            u: vec![128; cn],
            v: vec![128; cn],
            params: Vec::new(),
        }
    }

    /// Check the plane sizes against `header`.
    pub fn check_size(&self, header: &Y4mHeader) -> Result<(), String> {
        let (yn, cn) = header.plane_bytes();
        for (plane, len, want) in [
            ("Y", self.y.len(), yn),
            ("Cb", self.u.len(), cn),
            ("Cr", self.v.len(), cn),
        ] {
            if len != want {
                return Err(format!(
                    "the {plane} plane has {len} bytes, the header ({}x{} C{}) needs {want}",
                    header.width, header.height, header.colorspace
                ));
            }
        }
        Ok(())
    }

    /// Whether this frame's 4:2:0 chroma is stored per field under `conv` (see the module
    /// documentation): always false for layouts other than `420jpeg`, `420mpeg2`, `420`.
    pub fn field_chroma(&self, header: &Y4mHeader, conv: &YuvConversion) -> bool {
        if !header.colorspace.is_420() || header.colorspace.vertical_siting() != Siting::Between {
            return false;
        }
        match conv.chroma_fields {
            ChromaFields::Progressive => false,
            ChromaFields::Interlaced => true,
            ChromaFields::Auto => match header.interlace {
                Interlace::TopFieldFirst | Interlace::BottomFieldFirst => true,
                Interlace::Mixed => self
                    .params
                    .iter()
                    .find_map(|p| p.strip_prefix('I'))
                    .map(|i| {
                        let c: Vec<char> = i.chars().collect();
                        // Ixyz: z = chroma sampling (p / i / ?), y = temporal sampling.
                        match c.get(2) {
                            Some('i') => true,
                            Some('p') => false,
                            _ => c.get(1) == Some(&'i'),
                        }
                    })
                    .unwrap_or(false),
                Interlace::Progressive | Interlace::Unknown => false,
            },
        }
    }
}

/// Reads a YUV4MPEG2 stream: the header on construction, then frames one by one.
pub struct Y4mReader<R: Read> {
    inner: BufReader<R>,
    header: Y4mHeader,
    name: String,
    index: u64,
    line: Vec<u8>,
    failed: bool,
}

impl<R: Read> Y4mReader<R> {
    /// Read and check the header. `name` names the stream in messages (`stdin`, a path).
    pub fn new(inner: R, name: impl Into<String>) -> Result<Y4mReader<R>, Y4mError> {
        let name = name.into();
        let mut inner = BufReader::with_capacity(1 << 16, inner);
        let mut line = Vec::new();
        let header_err = |message: String| Y4mError::Header {
            name: name.clone(),
            message,
        };
        (&mut inner)
            .take(MAX_HEADER_BYTES as u64)
            .read_until(b'\n', &mut line)
            .map_err(|source| Y4mError::Io {
                name: name.clone(),
                context: "reading the y4m header".into(),
                source,
            })?;
        if line.is_empty() {
            return Err(header_err(
                "the stream is empty (no YUV4MPEG2 header)".into(),
            ));
        }
        let magic_ok =
            line.starts_with(MAGIC) && matches!(line.get(MAGIC.len()), None | Some(b' ' | b'\n'));
        if !magic_ok || line.last() != Some(&b'\n') {
            let message = if !magic_ok {
                format!(
                    "not a YUV4MPEG2 stream (it starts with \"{}\")",
                    escape(&line[..line.len().min(16)])
                )
            } else if line.len() >= MAX_HEADER_BYTES {
                format!("the header line is longer than {MAX_HEADER_BYTES} bytes")
            } else {
                "the stream ends inside the header line".to_string()
            };
            return Err(header_err(message));
        }
        let header = Y4mHeader::parse(&line).map_err(header_err)?;
        Ok(Y4mReader {
            inner,
            header,
            name,
            index: 0,
            line,
            failed: false,
        })
    }

    /// The stream's header.
    pub fn header(&self) -> &Y4mHeader {
        &self.header
    }

    /// The stream's name, as given to [`Y4mReader::new`].
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Frames read so far (the 0-based number of the next one).
    pub fn frames_read(&self) -> u64 {
        self.index
    }

    /// The next frame, or `None` at a clean end of the stream (right after a frame).
    /// Errors name the frame (0-based): a truncated frame, a malformed `FRAME` line.
    pub fn next_frame(&mut self) -> Result<Option<YuvFrame>, Y4mError> {
        let mut frame = YuvFrame::default();
        Ok(self.read_frame_into(&mut frame)?.then_some(frame))
    }

    /// [`Y4mReader::next_frame`] into an existing frame, reusing its buffers (no
    /// allocation when it already has the right sizes). Returns false at a clean end.
    pub fn read_frame_into(&mut self, frame: &mut YuvFrame) -> Result<bool, Y4mError> {
        let index = self.index;
        let frame_err = |name: &str, message: String| Y4mError::Frame {
            name: name.to_string(),
            frame: index,
            message,
        };
        self.line.clear();
        let n = (&mut self.inner)
            .take(MAX_FRAME_LINE_BYTES as u64)
            .read_until(b'\n', &mut self.line)
            .map_err(|source| self.io_err(source))?;
        if n == 0 {
            return Ok(false);
        }
        let line = &self.line;
        let magic_ok = line.starts_with(FRAME_MAGIC)
            && matches!(line.get(FRAME_MAGIC.len()), Some(b' ' | b'\n') | None);
        if line.last() != Some(&b'\n') || !magic_ok {
            let shown = escape(&line[..line.len().min(24)]);
            let message = if !magic_ok && !FRAME_MAGIC.starts_with(line) {
                format!("expected a `FRAME` line, found \"{shown}\"")
            } else if line.len() >= MAX_FRAME_LINE_BYTES {
                format!("the FRAME line is longer than {MAX_FRAME_LINE_BYTES} bytes")
            } else {
                format!("truncated: the stream ends inside the FRAME line (\"{shown}\")")
            };
            return Err(frame_err(&self.name, message));
        }
        let params = std::str::from_utf8(&line[FRAME_MAGIC.len()..line.len() - 1])
            .map_err(|_| frame_err(&self.name, "the FRAME line is not text".into()))?;
        frame.params.clear();
        frame.params.extend(
            params
                .split(' ')
                .filter(|p| !p.is_empty())
                .map(str::to_string),
        );
        let (yn, cn) = self.header.plane_bytes();
        let total = yn + 2 * cn;
        let mut got = 0;
        for (plane, want) in [(&mut frame.y, yn), (&mut frame.u, cn), (&mut frame.v, cn)] {
            let k = read_plane(&mut self.inner, plane, want).map_err(|source| Y4mError::Io {
                name: self.name.clone(),
                context: format!("reading y4m frame {index} (0-based)"),
                source,
            })?;
            got += k;
            if k < want {
                self.failed = true;
                return Err(frame_err(
                    &self.name,
                    format!("truncated (got {got} of {total} bytes)"),
                ));
            }
        }
        self.index += 1;
        Ok(true)
    }

    fn io_err(&self, source: io::Error) -> Y4mError {
        Y4mError::Io {
            name: self.name.clone(),
            context: format!("reading y4m frame {} (0-based)", self.index),
            source,
        }
    }
}

impl<R: Read> Iterator for Y4mReader<R> {
    type Item = Result<YuvFrame, Y4mError>;

    /// Frames until the end of the stream or the first error (which ends the iteration).
    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = self.next_frame().transpose();
        if matches!(r, Some(Err(_))) {
            self.failed = true;
        }
        r
    }
}

/// Fill `buf` with exactly `n` bytes when the stream has them; returns how many were
/// read (fewer at the end of the stream). A buffer that already has length `n` is
/// overwritten in place; otherwise it grows as the data arrives.
fn read_plane<R: Read>(r: &mut R, buf: &mut Vec<u8>, n: usize) -> io::Result<usize> {
    if buf.len() != n {
        buf.clear();
    }
    let mut filled = 0;
    while filled < n {
        if filled == buf.len() {
            let grow = (n - filled).min(READ_CHUNK.max(buf.len()));
            buf.resize(filled + grow, 0);
        }
        match r.read(&mut buf[filled..]) {
            Ok(0) => {
                buf.truncate(filled);
                return Ok(filled);
            }
            Ok(k) => filled += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// Writes a YUV4MPEG2 stream: the header on construction, then frames. Does not buffer:
/// give it a `BufWriter` (or a locked stdout in one) for small writes to coalesce.
pub struct Y4mWriter<W: Write> {
    inner: W,
    header: Y4mHeader,
    name: String,
    frames: u64,
}

impl<W: Write> Y4mWriter<W> {
    /// Check `header` ([`Y4mHeader::validate`]) and write it. `name` names the stream in
    /// messages (`stdout`, a path). Logs a warning when the line is longer than the 96
    /// bytes ffmpeg's demuxer accepts.
    pub fn new(
        mut inner: W,
        header: Y4mHeader,
        name: impl Into<String>,
    ) -> Result<Y4mWriter<W>, Y4mError> {
        let name = name.into();
        header.validate().map_err(|message| Y4mError::Header {
            name: name.clone(),
            message,
        })?;
        let line = header.to_line();
        if line.len() > FFMPEG_MAX_HEADER {
            log::warn!(
                "{name}: the y4m header is {} bytes long; ffmpeg reads at most {FFMPEG_MAX_HEADER}",
                line.len()
            );
        }
        inner
            .write_all(line.as_bytes())
            .map_err(|source| Y4mError::Io {
                name: name.clone(),
                context: "writing the y4m header".into(),
                source,
            })?;
        Ok(Y4mWriter {
            inner,
            header,
            name,
            frames: 0,
        })
    }

    /// The header written.
    pub fn header(&self) -> &Y4mHeader {
        &self.header
    }

    /// Frames written so far.
    pub fn frames_written(&self) -> u64 {
        self.frames
    }

    /// Write one frame: `FRAME`, its parameters, `\n`, then the planes (Y only for mono).
    /// The planes must match the header ([`YuvFrame::check_size`]) and the parameters be
    /// non-empty without spaces or newlines.
    pub fn write_frame(&mut self, frame: &YuvFrame) -> Result<(), Y4mError> {
        let index = self.frames;
        let frame_err = |message: String| Y4mError::Frame {
            name: self.name.clone(),
            frame: index,
            message,
        };
        frame.check_size(&self.header).map_err(frame_err)?;
        let mut line = Vec::with_capacity(16);
        line.extend_from_slice(FRAME_MAGIC);
        for p in &frame.params {
            if p.is_empty() || p.contains([' ', '\n', '\r']) {
                return Err(frame_err(format!("invalid FRAME parameter `{p}`")));
            }
            line.push(b' ');
            line.extend_from_slice(p.as_bytes());
        }
        line.push(b'\n');
        let mut write = |b: &[u8]| {
            self.inner.write_all(b).map_err(|source| Y4mError::Io {
                name: self.name.clone(),
                context: format!("writing y4m frame {index} (0-based)"),
                source,
            })
        };
        write(&line)?;
        write(&frame.y)?;
        write(&frame.u)?;
        write(&frame.v)?;
        self.frames += 1;
        Ok(())
    }

    /// Flush the underlying writer.
    pub fn flush(&mut self) -> Result<(), Y4mError> {
        self.inner.flush().map_err(|source| Y4mError::Io {
            name: self.name.clone(),
            context: "flushing the y4m stream".into(),
            source,
        })
    }

    /// Flush and return the underlying writer.
    pub fn into_inner(mut self) -> Result<W, Y4mError> {
        self.flush()?;
        Ok(self.inner)
    }
}

// ---------------------------------------------------------------------------------------
// Colour conversion
// ---------------------------------------------------------------------------------------

/// Y'CbCr matrix coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Matrix {
    /// ITU-R BT.601 (Kr 0.299, Kb 0.114): standard definition.
    Bt601,
    /// ITU-R BT.709 (Kr 0.2126, Kb 0.0722): HD.
    Bt709,
}

impl Matrix {
    /// BT.601 up to 576 lines, BT.709 above (what players assume for untagged video).
    pub fn for_height(height: u32) -> Matrix {
        if height <= 576 {
            Matrix::Bt601
        } else {
            Matrix::Bt709
        }
    }

    /// `(Kr, Kb)`.
    pub fn kr_kb(self) -> (f32, f32) {
        match self {
            Matrix::Bt601 => (0.299, 0.114),
            Matrix::Bt709 => (0.2126, 0.0722),
        }
    }
}

/// Y'CbCr quantisation range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Range {
    /// "TV" / "MPEG": Y 16-235, Cb/Cr 16-240 (128 ± 112).
    Limited,
    /// "PC" / "JPEG": Y 0-255, Cb/Cr 128 ± 127.5.
    Full,
}

/// How interlaced 4:2:0 chroma is resampled (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChromaFields {
    /// Per field for `It`/`Ib` streams and `Im` frames whose `I` parameter says so.
    Auto,
    /// Always as a progressive frame.
    Progressive,
    /// Always per field.
    Interlaced,
}

/// How Y'CbCr maps to RGB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct YuvConversion {
    pub matrix: Matrix,
    pub range: Range,
    pub chroma_fields: ChromaFields,
    /// Clip R'G'B' to [0, 1] (default). When false, colours outside the RGB cube (and
    /// super-whites) survive a Y'CbCr → linear f32 → Y'CbCr trip: the f32 values go below
    /// 0 or above 1 (the sRGB curve extended: linear below 0, power law above 1). The
    /// 8-bit outputs are always clipped.
    pub clip: bool,
}

impl YuvConversion {
    /// The defaults for a stream: [`Matrix::for_height`], the range of
    /// [`Y4mHeader::range_hint`] or limited, [`ChromaFields::Auto`], clipping.
    pub fn for_header(header: &Y4mHeader) -> YuvConversion {
        YuvConversion {
            matrix: Matrix::for_height(header.height),
            range: header.range_hint().unwrap_or(Range::Limited),
            chroma_fields: ChromaFields::Auto,
            clip: true,
        }
    }
}

/// Which pixels [`yuv_to_image`] makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RgbKind {
    /// [`Pixels::F32`]: linear light (the R'G'B' values sRGB-decoded), alpha 1.
    LinearF32,
    /// [`Pixels::U8`]: the R'G'B' values as 8-bit (sRGB-encoded) bytes, alpha 255.
    SrgbU8,
}

/// Scale factors and matrix for one conversion.
#[derive(Clone, Copy)]
struct Coeffs {
    /// Luma code of black and codes per unit.
    y_off: f32,
    y_scale: f32,
    /// Chroma codes per unit of Pb / Pr.
    c_scale: f32,
    kr: f32,
    kg: f32,
    kb: f32,
    /// R' = Y' + rv Pr; G' = Y' + gu Pb + gv Pr; B' = Y' + bu Pb.
    rv: f32,
    gu: f32,
    gv: f32,
    bu: f32,
}

impl Coeffs {
    fn new(conv: &YuvConversion) -> Coeffs {
        let (kr, kb) = conv.matrix.kr_kb();
        let kg = 1.0 - kr - kb;
        let (y_off, y_scale, c_scale) = match conv.range {
            Range::Limited => (16.0, 219.0, 224.0),
            Range::Full => (0.0, 255.0, 255.0),
        };
        Coeffs {
            y_off,
            y_scale,
            c_scale,
            kr,
            kg,
            kb,
            rv: 2.0 * (1.0 - kr),
            gu: -2.0 * kb * (1.0 - kb) / kg,
            gv: -2.0 * kr * (1.0 - kr) / kg,
            bu: 2.0 * (1.0 - kb),
        }
    }
}

/// A 2-tap linear interpolation: `a[i0] + w * (a[i1] - a[i0])`.
#[derive(Clone, Copy, Debug)]
struct Tap {
    i0: u32,
    i1: u32,
    w: f32,
}

/// For each luma row, the chroma rows it interpolates between.
fn vertical_up_taps(h: usize, ch: usize, siting: Siting, fields: bool) -> Vec<Tap> {
    let lerp = |p: f32, n: usize| -> (usize, usize, f32) {
        let p = p.clamp(0.0, (n - 1) as f32);
        let i0 = p.floor() as usize;
        let i1 = (i0 + 1).min(n - 1);
        (i0, i1, p - i0 as f32)
    };
    (0..h)
        .map(|y| {
            if siting == Siting::Full {
                return Tap {
                    i0: y as u32,
                    i1: y as u32,
                    w: 0.0,
                };
            }
            if fields {
                let mut f = y & 1;
                // Chroma rows of field f: f, f + 2, ...
                let mut nk = (ch + 1 - f) / 2;
                if nk == 0 {
                    f = 0;
                    nk = ch.div_ceil(2);
                }
                let off = if y & 1 == 0 { 0.25 } else { 0.75 };
                let (k0, k1, w) = lerp(((y / 2) as f32 - off) / 2.0, nk);
                return Tap {
                    i0: (2 * k0 + f) as u32,
                    i1: (2 * k1 + f) as u32,
                    w,
                };
            }
            let p = match siting {
                Siting::Between => (y as f32 - 0.5) / 2.0,
                _ => y as f32 / 2.0,
            };
            let (i0, i1, w) = lerp(p, ch);
            Tap {
                i0: i0 as u32,
                i1: i1 as u32,
                w,
            }
        })
        .collect()
}

/// For each chroma row, up to three (luma row, weight) taps of the downsampling filter.
fn vertical_down_taps(h: usize, ch: usize, siting: Siting, fields: bool) -> Vec<[(u32, f32); 3]> {
    let last = h - 1;
    (0..ch)
        .map(|c| {
            if siting == Siting::Full {
                return [(c as u32, 1.0), (0, 0.0), (0, 0.0)];
            }
            if fields {
                let (f, k) = (c & 1, c >> 1);
                let r0 = 4 * k + f;
                let r1 = if r0 + 2 <= last { r0 + 2 } else { r0 };
                let (w0, w1) = if f == 0 { (0.75, 0.25) } else { (0.25, 0.75) };
                return [(r0 as u32, w0), (r1 as u32, w1), (0, 0.0)];
            }
            let r = 2 * c;
            match siting {
                Siting::Between => [(r as u32, 0.5), ((r + 1).min(last) as u32, 0.5), (0, 0.0)],
                _ => [
                    (r.saturating_sub(1) as u32, 0.25),
                    (r as u32, 0.5),
                    ((r + 1).min(last) as u32, 0.25),
                ],
            }
        })
        .collect()
}

/// Upsample one chroma row (`src`, chroma width `n`) to luma width (`dst`, `2n - 1` or
/// `2n`): bilinear at the siting's sample positions, edges clamped.
#[inline]
fn upsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = src.len();
    if siting == Siting::Full {
        dst.copy_from_slice(src);
        return;
    }
    // Pairs (2i, 2i+1) for i in 1..n-1 from src[i-1], src[i], src[i+1]; the first and
    // the last pair below.
    if n >= 3 {
        let inner = dst[2..2 * (n - 1)].chunks_exact_mut(2);
        let it = inner.zip(src.iter().zip(&src[1..]).zip(&src[2..]));
        match siting {
            Siting::Between => {
                for (d, ((&p, &c), &nx)) in it {
                    d[0] = 0.75 * c + 0.25 * p;
                    d[1] = 0.75 * c + 0.25 * nx;
                }
            }
            _ => {
                for (d, ((_, &c), &nx)) in it {
                    d[0] = c;
                    d[1] = 0.5 * (c + nx);
                }
            }
        }
    }
    for i in [0, n - 1] {
        let c = src[i];
        let (p, nx) = (src[i.saturating_sub(1)], src[(i + 1).min(n - 1)]);
        let (even, odd) = match siting {
            Siting::Between => (0.75 * c + 0.25 * p, 0.75 * c + 0.25 * nx),
            _ => (c, 0.5 * (c + nx)),
        };
        dst[2 * i] = even;
        if let Some(o) = dst.get_mut(2 * i + 1) {
            *o = odd;
        }
    }
}

/// Downsample one full-width row (`src`) to chroma width (`dst`): a 2-tap box for
/// chroma between columns, [1 2 1]/4 for co-sited chroma, edges clamped.
#[inline]
fn downsample_row(src: &[f32], dst: &mut [f32], siting: Siting) {
    let n = dst.len();
    let last = src.len() - 1;
    match siting {
        Siting::Full => dst.copy_from_slice(src),
        Siting::Between => {
            for (d, pair) in dst.iter_mut().zip(src.chunks_exact(2)) {
                *d = 0.5 * (pair[0] + pair[1]);
            }
            if src.len() % 2 == 1 {
                dst[n - 1] = src[last];
            }
        }
        Siting::CoSited => {
            dst[0] = 0.75 * src[0] + 0.25 * src[1.min(last)];
            if n >= 2 {
                // dst[i] from src[2i-1], src[2i], src[2i+1] for i in 1..
                // (the last one clamped when the width is odd: src[2i+1] missing).
                let pairs = src[1..].chunks_exact(2).zip(src[2..].chunks(2));
                for (d, (ab, next)) in dst[1..].iter_mut().zip(pairs) {
                    let (a, b) = (ab[0], ab[1]);
                    let c = next.get(1).copied().unwrap_or(b);
                    *d = 0.25 * a + 0.5 * b + 0.25 * c;
                }
            }
        }
    }
}

// The sRGB curve, vectorisable: below the knee the exact linear segment, above it a
// polynomial fitted (least squares on Chebyshev nodes, evaluated in f32 on t in [-1, 1]).
// Errors against the exact formula: decode below 3e-6, encode below 4e-6 (0.001 of an
// 8-bit code); see the unit test.

/// Decode: `((x + 0.055) / 1.055)^2.4` on [0.04045, 1], t = (2x - 1.04045) / 0.95955.
const DEC_POLY: [f32; 9] = [
    0.2332408,
    0.46688867,
    0.27259746,
    0.030351264,
    -0.0038336907,
    0.0008825551,
    -0.0002557971,
    0.00031066535,
    -0.00018283911,
];
const DEC_T_SCALE: f32 = 2.0 / (1.0 - 0.04045);
const DEC_T_OFFSET: f32 = -(1.0 + 0.04045) / (1.0 - 0.04045);

/// Encode: `1.055 x^(1/2.4) - 0.055` as a polynomial in s = x^(1/4) on
/// [0.0031308^(1/4), 1], t = (2s - 1 - s0) / (1 - s0).
const ENC_POLY: [f32; 8] = [
    0.41838986,
    0.48712528,
    0.10025644,
    -0.00687218,
    0.0013879355,
    -0.0004124164,
    0.00018937996,
    -0.0000644815,
];
const ENC_S0: f32 = 0.236_545_03;
const ENC_T_SCALE: f32 = 2.0 / (1.0 - ENC_S0);
const ENC_T_OFFSET: f32 = -(1.0 + ENC_S0) / (1.0 - ENC_S0);

#[inline(always)]
fn horner<const N: usize>(c: &[f32; N], t: f32) -> f32 {
    let mut acc = c[N - 1];
    for i in (0..N - 1).rev() {
        acc = acc * t + c[i];
    }
    acc
}

/// sRGB-encoded value in [0, 1] to linear light. Branch-free (both sides are computed
/// and one selected), so loops over it vectorise.
#[inline(always)]
fn srgb_decode_unit(x: f32) -> f32 {
    let p = horner(&DEC_POLY, x * DEC_T_SCALE + DEC_T_OFFSET);
    let lin = x * (1.0 / 12.92);
    let v = if x <= 0.04045 { lin } else { p };
    // Exactly 1 at 1 (the polynomial is 1.2e-6 short).
    if x >= 1.0 {
        1.0
    } else {
        v
    }
}

/// sRGB-encoded value to linear light for any `x`: [`srgb_decode_unit`] in [0, 1], the
/// formula's linear segment below 0, its power law above 1.
#[inline]
fn srgb_decode(x: f32) -> f32 {
    if x > 1.0 {
        srgb::srgb_to_linear(x)
    } else {
        srgb_decode_unit(x)
    }
}

/// Linear light in [0, 1] to an sRGB-encoded value, branch-free like
/// [`srgb_decode_unit`]; NaN gives NaN.
#[inline(always)]
fn srgb_encode_unit(x: f32) -> f32 {
    let s = x.sqrt().sqrt();
    let p = horner(&ENC_POLY, s * ENC_T_SCALE + ENC_T_OFFSET);
    let lin = x * 12.92;
    let v = if x <= 0.003_130_8 { lin } else { p };
    if x >= 1.0 {
        1.0
    } else {
        v
    }
}

/// Linear light to an sRGB-encoded value for any `x` (see [`srgb_decode`]).
#[inline]
fn srgb_encode(x: f32) -> f32 {
    if x > 1.0 {
        srgb::linear_to_srgb(x)
    } else if x < 0.0 {
        x * 12.92
    } else {
        srgb_encode_unit(x)
    }
}

/// Round to an 8-bit code (ties to even), saturating; NaN gives 0. Branch-free: adding
/// 1.5 * 2^23 leaves the rounded integer in the low mantissa bits.
#[inline(always)]
#[allow(clippy::manual_clamp)] // `max` first maps NaN to 0; `clamp` would keep it.
fn to_code(v: f32) -> u8 {
    ((v.max(0.0).min(255.0) + 12_582_912.0).to_bits() & 0xff) as u8
}

/// Threads for a job of `pixels` pixels over `rows` rows.
fn threads_for(pixels: usize, rows: usize) -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    if pixels < 1 << 16 {
        return 1;
    }
    let cores = *CORES.get_or_init(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    cores.min(pixels >> 15).min(rows.max(1)).max(1)
}

/// Check that a frame and an RGBA buffer of `len` samples fit `header`.
fn check_rgba(header: &Y4mHeader, len: usize) -> Result<(), String> {
    header.validate()?;
    let want = header.width as usize * header.height as usize * 4;
    if len != want {
        return Err(format!(
            "{len} RGBA samples given for a {}x{} frame ({want} expected)",
            header.width, header.height
        ));
    }
    Ok(())
}

/// Convert a frame to RGBA pixels of any type. For each output row,
/// `emit(out_row, r, g, b)` stores the row from its R'G'B' values (unclipped, scaled by
/// `scale`: 1.0 is the unit range), given as three planar rows (structure of arrays, so
/// that the per-pixel arithmetic vectorises; `emit` may overwrite them).
fn yuv_to_rgba<T: Send>(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [T],
    scale: f32,
    emit: impl Fn(&mut [T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, out.len())?;
    frame.check_size(header)?;
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv);
    // Y' = (Y - y_off) * ys; Pb = (Cb - 128) * cs, both times `scale`.
    let ys = scale / k.y_scale;
    let y0s = -k.y_off * ys;
    let cs = scale / k.c_scale;
    let vtaps = if chroma.has_chroma() {
        vertical_up_taps(
            h,
            ch,
            chroma.vertical_siting(),
            frame.field_chroma(header, conv),
        )
    } else {
        Vec::new()
    };
    let hsiting = chroma.horizontal_siting();
    let threads = threads_for(w * h, h);
    let band = h.div_ceil(threads);
    let work = |y0: usize, out: &mut [T]| {
        let mut cu = vec![0f32; cw];
        let mut cv = vec![0f32; cw];
        let mut fu = vec![0f32; w];
        let mut fv = vec![0f32; w];
        let mut rr = vec![0f32; w];
        let mut gg = vec![0f32; w];
        let mut bb = vec![0f32; w];
        for (dy, orow) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = y0 + dy;
            let yrow = &frame.y[y * w..(y + 1) * w];
            if !chroma.has_chroma() {
                for (d, &l) in rr.iter_mut().zip(yrow) {
                    *d = l as f32 * ys + y0s;
                }
                gg.copy_from_slice(&rr);
                bb.copy_from_slice(&rr);
                emit(orow, &mut rr, &mut gg, &mut bb);
                continue;
            }
            let t = vtaps[y];
            for (plane, crow) in [(&frame.u, &mut cu), (&frame.v, &mut cv)] {
                let r0 = &plane[t.i0 as usize * cw..][..cw];
                let r1 = &plane[t.i1 as usize * cw..][..cw];
                let (w0, w1) = ((1.0 - t.w) * cs, t.w * cs);
                for ((d, &a), &b) in crow.iter_mut().zip(r0).zip(r1) {
                    *d = a as f32 * w0 + b as f32 * w1 - 128.0 * cs;
                }
            }
            upsample_row(&cu, &mut fu, hsiting);
            upsample_row(&cv, &mut fv, hsiting);
            for (((((r, g), b), &l), &pb), &pr) in rr
                .iter_mut()
                .zip(gg.iter_mut())
                .zip(bb.iter_mut())
                .zip(yrow)
                .zip(&fu)
                .zip(&fv)
            {
                let yv = l as f32 * ys + y0s;
                *r = yv + k.rv * pr;
                *g = yv + k.gu * pb + k.gv * pr;
                *b = yv + k.bu * pb;
            }
            emit(orow, &mut rr, &mut gg, &mut bb);
        }
    };
    if threads == 1 {
        work(0, out);
    } else {
        std::thread::scope(|s| {
            for (i, chunk) in out.chunks_mut(band * w * 4).enumerate() {
                let work = &work;
                s.spawn(move || work(i * band, chunk));
            }
        });
    }
    Ok(())
}

/// Convert a frame to 8-bit RGBA (the R'G'B' values, clipped and rounded; alpha 255).
/// `out` must hold `width * height * 4` bytes.
pub fn yuv_to_rgba_u8(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [u8],
) -> Result<(), String> {
    yuv_to_rgba(frame, header, conv, out, 255.0, |row, r, g, b| {
        for (((px, &r), &g), &b) in row.chunks_exact_mut(4).zip(&*r).zip(&*g).zip(&*b) {
            let rgba = u32::from_le_bytes([to_code(r), to_code(g), to_code(b), 255]);
            px.copy_from_slice(&rgba.to_le_bytes());
        }
    })
}

/// Convert a frame to linear-light RGBA floats (R'G'B' sRGB-decoded; alpha 1). Clipped to
/// [0, 1] unless `conv.clip` is false. `out` must hold `width * height * 4` floats.
pub fn yuv_to_rgba_f32(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    out: &mut [f32],
) -> Result<(), String> {
    let clip = conv.clip;
    yuv_to_rgba(frame, header, conv, out, 1.0, |row, r, g, b| {
        for plane in [&mut *r, &mut *g, &mut *b] {
            if clip {
                for v in plane.iter_mut() {
                    *v = srgb_decode_unit(v.clamp(0.0, 1.0));
                }
            } else {
                for v in plane.iter_mut() {
                    *v = srgb_decode(*v);
                }
            }
        }
        for (((px, &r), &g), &b) in row.chunks_exact_mut(4).zip(&*r).zip(&*g).zip(&*b) {
            px.copy_from_slice(&[r, g, b, 1.0]);
        }
    })
}

/// Convert a frame to an [`Image`] of `kind`. The image's [`SourceInfo`] says 8-bit,
/// opaque, integer; its format is [`FileFormat::Pnm`] (the closest raw-samples format;
/// there is no y4m file format).
pub fn yuv_to_image(
    frame: &YuvFrame,
    header: &Y4mHeader,
    conv: &YuvConversion,
    kind: RgbKind,
) -> Result<Image, String> {
    check_rgba(header, header.width as usize * header.height as usize * 4)?;
    let n = header.width as usize * header.height as usize * 4;
    let pixels = match kind {
        RgbKind::SrgbU8 => {
            let mut out = vec![0u8; n];
            yuv_to_rgba_u8(frame, header, conv, &mut out)?;
            Pixels::U8(out)
        }
        RgbKind::LinearF32 => {
            let mut out = vec![0f32; n];
            yuv_to_rgba_f32(frame, header, conv, &mut out)?;
            Pixels::F32(out)
        }
    };
    Ok(Image {
        width: header.width,
        height: header.height,
        pixels,
        source: SourceInfo {
            format: FileFormat::Pnm,
            bit_depth: 8,
            has_alpha: false,
            float: false,
        },
    })
}

/// Convert RGBA pixels of any type to a frame: `load(in_row, r, g, b)` stores the R'G'B'
/// values of one input row into three planar rows (alpha is ignored). `frame.params` are kept (they decide
/// the chroma fields of `Im` streams).
fn rgba_to_yuv<T: Sync>(
    rgba: &[T],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
    load: impl Fn(&[T], &mut [f32], &mut [f32], &mut [f32]) + Sync,
) -> Result<(), String> {
    check_rgba(header, rgba.len())?;
    let (w, h) = (header.width as usize, header.height as usize);
    let chroma = header.colorspace;
    let (cw, ch) = chroma.chroma_size(header.width, header.height);
    let k = Coeffs::new(conv);
    frame.y.resize(w * h, 0);
    frame.u.resize(cw * ch, 0);
    frame.v.resize(cw * ch, 0);
    let fields = frame.field_chroma(header, conv);
    let hsiting = chroma.horizontal_siting();
    let threads = threads_for(w * h, h);
    // Y' code = y_off + y_scale * Y'; chroma code = 128 + c_scale * P.
    let (ky_r, ky_g, ky_b) = (k.y_scale * k.kr, k.y_scale * k.kg, k.y_scale * k.kb);
    let (pb_s, pr_s) = (0.5 / (1.0 - k.kb), 0.5 / (1.0 - k.kr));
    // Pass 1: luma, and Pb / Pr (in code units, without the 128 offset) of every row,
    // downsampled across to chroma width.
    let mut pb = vec![0f32; if chroma.has_chroma() { cw * h } else { 0 }];
    let mut pr = vec![0f32; pb.len()];
    {
        let band = h.div_ceil(threads);
        let pass1 = |y0: usize, yout: &mut [u8], pbo: &mut [f32], pro: &mut [f32]| {
            let mut rr = vec![0f32; w];
            let mut gg = vec![0f32; w];
            let mut bb = vec![0f32; w];
            for (dy, yrow) in yout.chunks_exact_mut(w).enumerate() {
                let y = y0 + dy;
                load(&rgba[y * w * 4..(y + 1) * w * 4], &mut rr, &mut gg, &mut bb);
                if !chroma.has_chroma() {
                    for (((d, &r), &g), &b) in yrow.iter_mut().zip(&rr).zip(&gg).zip(&bb) {
                        *d = to_code(k.y_off + ky_r * r + ky_g * g + ky_b * b);
                    }
                    continue;
                }
                // Y' into the luma row; Pb and Pr in place of B' and R'.
                for ((d, r), (g, b)) in yrow
                    .iter_mut()
                    .zip(rr.iter_mut())
                    .zip(gg.iter().zip(bb.iter_mut()))
                {
                    let yl = k.kr * *r + k.kg * *g + k.kb * *b;
                    *d = to_code(k.y_off + k.y_scale * yl);
                    *b = k.c_scale * pb_s * (*b - yl);
                    *r = k.c_scale * pr_s * (*r - yl);
                }
                downsample_row(&bb, &mut pbo[dy * cw..(dy + 1) * cw], hsiting);
                downsample_row(&rr, &mut pro[dy * cw..(dy + 1) * cw], hsiting);
            }
        };
        if threads == 1 {
            pass1(0, &mut frame.y, &mut pb, &mut pr);
        } else {
            std::thread::scope(|s| {
                let cband = if chroma.has_chroma() { band * cw } else { 1 };
                let mut pbc = pb.chunks_mut(cband);
                let mut prc = pr.chunks_mut(cband);
                for (i, yc) in frame.y.chunks_mut(band * w).enumerate() {
                    let pbo = pbc.next().unwrap_or_default();
                    let pro = prc.next().unwrap_or_default();
                    let pass1 = &pass1;
                    s.spawn(move || pass1(i * band, yc, pbo, pro));
                }
            });
        }
    }
    if !chroma.has_chroma() {
        return Ok(());
    }
    // Pass 2: vertical downsampling into the chroma planes.
    let taps = vertical_down_taps(h, ch, chroma.vertical_siting(), fields);
    let band = ch.div_ceil(threads);
    let pass2 = |c0: usize, uo: &mut [u8], vo: &mut [u8]| {
        for (dc, (urow, vrow)) in uo
            .chunks_exact_mut(cw)
            .zip(vo.chunks_exact_mut(cw))
            .enumerate()
        {
            let t = taps[c0 + dc];
            for (src, dst) in [(&pb, urow), (&pr, vrow)] {
                let r0 = &src[t[0].0 as usize * cw..][..cw];
                let r1 = &src[t[1].0 as usize * cw..][..cw];
                let r2 = &src[t[2].0 as usize * cw..][..cw];
                let (w0, w1, w2) = (t[0].1, t[1].1, t[2].1);
                for (d, ((&a, &b), &c)) in dst.iter_mut().zip(r0.iter().zip(r1).zip(r2)) {
                    *d = to_code(128.0 + w0 * a + w1 * b + w2 * c);
                }
            }
        }
    };
    if threads == 1 {
        pass2(0, &mut frame.u, &mut frame.v);
    } else {
        std::thread::scope(|s| {
            for (i, (uc, vc)) in frame
                .u
                .chunks_mut(band * cw)
                .zip(frame.v.chunks_mut(band * cw))
                .enumerate()
            {
                let pass2 = &pass2;
                s.spawn(move || pass2(i * band, uc, vc));
            }
        });
    }
    Ok(())
}

/// Convert 8-bit RGBA (sRGB-encoded R'G'B' bytes; alpha ignored) into `frame`, resizing its
/// planes to `header` and keeping its `params`.
pub fn rgba_u8_to_yuv(
    rgba: &[u8],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
) -> Result<(), String> {
    const INV: f32 = 1.0 / 255.0;
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            *r = px[0] as f32 * INV;
            *g = px[1] as f32 * INV;
            *b = px[2] as f32 * INV;
        }
    })
}

/// Convert linear-light RGBA floats (sRGB-encoded to R'G'B'; clipped to [0, 1] first
/// unless `conv.clip` is false; alpha ignored) into `frame`, resizing its planes to
/// `header` and keeping its `params`. NaN counts as 0.
pub fn rgba_f32_to_yuv(
    rgba: &[f32],
    header: &Y4mHeader,
    conv: &YuvConversion,
    frame: &mut YuvFrame,
) -> Result<(), String> {
    let clip = conv.clip;
    rgba_to_yuv(rgba, header, conv, frame, |row, r, g, b| {
        for (px, (r, (g, b))) in row
            .chunks_exact(4)
            .zip(r.iter_mut().zip(g.iter_mut().zip(b.iter_mut())))
        {
            (*r, *g, *b) = (px[0], px[1], px[2]);
        }
        for plane in [r, g, b] {
            if clip {
                for v in plane.iter_mut() {
                    // `max` first: NaN becomes 0 (`clamp` would keep it).
                    #[allow(clippy::manual_clamp)]
                    let c = v.max(0.0).min(1.0);
                    *v = srgb_encode_unit(c);
                }
            } else {
                for v in plane.iter_mut() {
                    *v = srgb_encode(*v);
                }
            }
        }
    })
}

/// Convert an [`Image`] (U8: sRGB bytes; F32: linear light) to a new frame for `header`
/// (whose size must match the image's). The frame has no `FRAME` parameters.
pub fn image_to_yuv(
    image: &Image,
    header: &Y4mHeader,
    conv: &YuvConversion,
) -> Result<YuvFrame, String> {
    if image.width != header.width || image.height != header.height {
        return Err(format!(
            "the image is {}x{} but the y4m stream is {}x{}",
            image.width, image.height, header.width, header.height
        ));
    }
    let mut frame = YuvFrame::default();
    match &image.pixels {
        Pixels::U8(v) => rgba_u8_to_yuv(v, header, conv, &mut frame)?,
        Pixels::F32(v) => rgba_f32_to_yuv(v, header, conv, &mut frame)?,
    }
    Ok(frame)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curves_are_accurate() {
        let mut worst_d = 0f64;
        let mut worst_e = 0f64;
        for i in 0..=1_000_000 {
            let x = i as f32 / 1_000_000.0;
            let exact_d = srgb::srgb_to_linear_f64(x as f64);
            let exact_e = srgb::linear_to_srgb_f64(x as f64);
            worst_d = worst_d.max((srgb_decode(x) as f64 - exact_d).abs());
            worst_e = worst_e.max((srgb_encode(x) as f64 - exact_e).abs());
        }
        assert!(worst_d < 3e-6, "decode error {worst_d:e}");
        assert!(worst_e < 4e-6, "encode error {worst_e:e}");
        assert_eq!(srgb_decode(0.0), 0.0);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert_eq!(srgb_decode(1.0), 1.0);
        assert_eq!(srgb_encode(1.0), 1.0);
        assert!((srgb_decode(1.5) - srgb::srgb_to_linear(1.5)).abs() < 1e-6);
        assert!((srgb_decode(-0.5) + 0.5 / 12.92).abs() < 1e-7);
        assert!((srgb_encode(-0.5) + 0.5 * 12.92).abs() < 1e-6);
        // Every 8-bit code survives decode, encode and rounding.
        for v in 0..=255u8 {
            let back = srgb_encode_unit(srgb_decode_unit(v as f32 / 255.0)) * 255.0;
            assert_eq!(to_code(back), v);
        }
    }

    #[test]
    fn rounding_to_codes() {
        assert_eq!(to_code(-3.0), 0);
        assert_eq!(to_code(0.49), 0);
        assert_eq!(to_code(0.51), 1);
        assert_eq!(to_code(254.6), 255);
        assert_eq!(to_code(1e9), 255);
        assert_eq!(to_code(f32::NAN), 0);
        assert_eq!(to_code(f32::INFINITY), 255);
        assert_eq!(to_code(f32::NEG_INFINITY), 0);
        for v in 0..=255u8 {
            assert_eq!(to_code(v as f32), v);
        }
    }

    #[test]
    fn field_taps_stay_in_their_field() {
        for h in [1usize, 2, 3, 4, 5, 8, 9, 576] {
            let ch = h.div_ceil(2);
            for (y, t) in vertical_up_taps(h, ch, Siting::Between, true)
                .iter()
                .enumerate()
            {
                assert!((t.i0 as usize) < ch && (t.i1 as usize) < ch, "h {h} y {y}");
                if ch >= 2 {
                    assert_eq!(t.i0 as usize & 1, y & 1, "h {h} y {y}");
                    assert_eq!(t.i1 as usize & 1, y & 1, "h {h} y {y}");
                }
            }
            for (c, t) in vertical_down_taps(h, ch, Siting::Between, true)
                .iter()
                .enumerate()
            {
                for &(r, w) in t {
                    if w > 0.0 {
                        assert!((r as usize) < h);
                        assert_eq!(r as usize & 1, c & 1, "h {h} c {c}");
                    }
                }
            }
        }
    }
}
