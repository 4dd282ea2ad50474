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

use super::IoError;

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

pub use super::yuv::*;

#[cfg(test)]
mod tests {
    use super::super::srgb;
    use super::super::yuv::*;
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
