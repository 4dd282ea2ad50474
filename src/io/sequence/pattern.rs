//! Numbered file-name patterns (`%04d`) and frame ranges (`--frames`).

use super::*;
use std::fmt;

/// How a pattern pads the frame number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Padding {
    /// `%d`: no padding.
    None,
    /// `%0Nd`: zeros up to N digits.
    Zeros(usize),
    /// `%Nd`: spaces up to N characters.
    Spaces(usize),
}

/// Widest accepted padding (`%020d`; u64 has at most 20 digits).
const MAX_PAD_WIDTH: usize = 20;

/// A parsed printf-style frame pattern such as `out/frame_%04d.png`.
///
/// Matching is exact: a file name matches when it is the pattern formatted with its own
/// number, so `%04d` matches `0007.png` and `12345.png` but not `7.png` or `00007.png`, and
/// `%d` matches `7.png` but not `007.png`. This makes [`FramePattern::format`] and
/// [`FramePattern::match_file_name`] inverse to each other.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FramePattern {
    pattern: String,
    /// Everything before the conversion with `%%` resolved, folder included.
    head: String,
    /// The file name part of `head`.
    name_prefix: String,
    /// Everything after the conversion with `%%` resolved (never contains a separator).
    suffix: String,
    /// The literal folder (`.` when the pattern has none).
    dir: PathBuf,
    padding: Padding,
}

/// The `[0][width]` of a conversion after its `%`, up to and with its `d`; an error for
/// another conversion or one cut short.
fn conversion_spec(
    chars: &mut std::iter::Peekable<std::str::CharIndices>,
) -> Result<String, String> {
    let mut spec = String::new();
    while let Some(&(_, d)) = chars.peek() {
        if d.is_ascii_digit() {
            spec.push(d);
            chars.next();
        } else {
            break;
        }
    }
    // (how a conversion is written, in the errors)
    let forms = "(use %d, %04d or %4d; %% for a literal %)";
    match chars.next() {
        Some((_, 'd')) => Ok(spec),
        Some((_, other)) => Err(format!("unsupported conversion `%{spec}{other}` {forms}")),
        None => Err(format!(
            "incomplete conversion `%{spec}` at the end {forms}"
        )),
    }
}

/// The padding a conversion's `[0][width]` asks for: zeros with a leading `0`, spaces
/// otherwise, none for a width of 0 or 1.
fn padding_of(spec: &str) -> Result<Padding, String> {
    let zero = spec.starts_with('0');
    let width: usize = if spec.is_empty() {
        0
    } else {
        spec.parse()
            .ok()
            .filter(|w| *w <= MAX_PAD_WIDTH)
            .ok_or_else(|| {
                format!("padding width `{spec}` is too large (at most {MAX_PAD_WIDTH})")
            })?
    };
    Ok(match (width, zero) {
        (0 | 1, _) => Padding::None,
        (w, true) => Padding::Zeros(w),
        (w, false) => Padding::Spaces(w),
    })
}

impl FramePattern {
    /// Parse a pattern: exactly one `%d`, `%0Nd` or `%Nd` conversion (N up to 20), in the
    /// file name (not in a folder name); `%%` is a literal `%`. The error says what is
    /// wrong, without the pattern itself.
    pub fn parse(pattern: &str) -> Result<FramePattern, String> {
        let mut head = String::new();
        let mut suffix = String::new();
        let mut padding = None;
        let mut chars = pattern.char_indices().peekable();
        while let Some((_, c)) = chars.next() {
            let out = if padding.is_some() {
                &mut suffix
            } else {
                &mut head
            };
            if c != '%' {
                out.push(c);
                continue;
            }
            if let Some((_, '%')) = chars.peek() {
                chars.next();
                out.push('%');
                continue;
            }
            // A conversion: [0][width]d
            let spec = conversion_spec(&mut chars)?;
            if padding.is_some() {
                return Err(
                    "more than one frame number conversion; use exactly one (%% for a literal %)"
                        .to_string(),
                );
            }
            padding = Some(padding_of(&spec)?);
        }
        let Some(padding) = padding else {
            return Err(
                "no frame number conversion (use %d, %04d or %4d; %% for a literal %)".to_string(),
            );
        };
        if suffix.contains(is_separator) {
            return Err(
                "the frame number must be in the file name, not in a folder name".to_string(),
            );
        }
        let split = head.rfind(is_separator).map(|i| i + 1).unwrap_or(0);
        let name_prefix = head[split..].to_string();
        let dir = if split == 0 {
            PathBuf::from(".")
        } else {
            PathBuf::from(&head[..split])
        };
        Ok(FramePattern {
            pattern: pattern.to_string(),
            head,
            name_prefix,
            suffix,
            dir,
            padding,
        })
    }

    /// The pattern as written.
    pub fn as_str(&self) -> &str {
        &self.pattern
    }

    /// The literal folder the files are in (`.` when the pattern names none).
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The padding of the frame number.
    pub fn padding(&self) -> Padding {
        self.padding
    }

    /// The frame number as the pattern writes it (`7` → `0007` for `%04d`, `   7` for `%4d`).
    pub fn format_number(&self, n: u64) -> String {
        match self.padding {
            Padding::None => n.to_string(),
            Padding::Zeros(w) => format!("{n:0w$}"),
            Padding::Spaces(w) => format!("{n:>w$}"),
        }
    }

    /// The path of frame `n`: the pattern with the number formatted into it.
    pub fn format(&self, n: u64) -> PathBuf {
        PathBuf::from(format!(
            "{}{}{}",
            self.head,
            self.format_number(n),
            self.suffix
        ))
    }

    /// The frame number of a file name (no folder) that matches the pattern exactly (see
    /// the type's documentation), or `None`.
    pub fn match_file_name(&self, name: &str) -> Option<u64> {
        let field = name
            .strip_prefix(self.name_prefix.as_str())?
            .strip_suffix(self.suffix.as_str())?;
        let digits = match self.padding {
            Padding::Spaces(_) => field.trim_start_matches(' '),
            _ => field,
        };
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let n: u64 = digits.parse().ok()?;
        (self.format_number(n) == field).then_some(n)
    }
}

impl fmt::Display for FramePattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.pattern)
    }
}

/// An inclusive range of frame numbers, from `--frames A..B`. Open ends are stored as
/// `0` and `u64::MAX`, so that [`FrameRange::contains`] and [`InputSequence::slice`]
/// resolve them against the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameRange {
    /// First frame number (inclusive; `0` for an open start).
    pub start: u64,
    /// Last frame number (inclusive; `u64::MAX` for an open end).
    pub end: u64,
}

impl FrameRange {
    /// Every frame.
    pub const ALL: FrameRange = FrameRange {
        start: 0,
        end: u64::MAX,
    };

    /// Whether frame `n` is in the range.
    pub fn contains(&self, n: u64) -> bool {
        self.start <= n && n <= self.end
    }

    /// Number of frame numbers in the range (saturating).
    pub fn len(&self) -> u64 {
        (self.end - self.start).saturating_add(1)
    }

    /// Always false: a range holds at least one number.
    pub fn is_empty(&self) -> bool {
        false
    }
}

impl fmt::Display for FrameRange {
    /// `A..B`, with open ends left out (`10..`, `..20`, `..`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.start != 0 {
            write!(f, "{}", self.start)?;
        }
        f.write_str("..")?;
        if self.end != u64::MAX {
            write!(f, "{}", self.end)?;
        }
        Ok(())
    }
}

/// Parse a `--frames` argument: `A..B` (inclusive: `10..20` is 11 frames), `A..=B` (the
/// same), `A..`, `..B`, `..` (everything) or a single number `N` (`N..N`). Numbers are
/// frame numbers as in the file names, not positions. Errors say what is wrong and show
/// the accepted forms.
pub fn parse_frames(arg: &str) -> Result<FrameRange, String> {
    const FORMS: &str = "expected A..B (inclusive), A.., ..B or N";
    let s = arg.trim();
    if s.is_empty() {
        return Err(format!("empty frame range ({FORMS})"));
    }
    let number = |t: &str, what: &str| -> Result<u64, String> {
        if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(format!(
                "invalid {what} `{t}` in frame range `{arg}` ({FORMS})"
            ));
        }
        t.parse()
            .map_err(|_| format!("{what} `{t}` in frame range `{arg}` is too large"))
    };
    let Some((a, b)) = s.split_once("..") else {
        let n = number(s, "frame number")?;
        return Ok(FrameRange { start: n, end: n });
    };
    let b = b.strip_prefix('=').unwrap_or(b);
    if b.contains("..") || a.contains('.') || b.contains('.') {
        return Err(format!("invalid frame range `{arg}` ({FORMS})"));
    }
    let start = if a.is_empty() {
        0
    } else {
        number(a.trim(), "start")?
    };
    let end = if b.is_empty() {
        u64::MAX
    } else {
        number(b.trim(), "end")?
    };
    if end < start {
        return Err(format!(
            "frame range `{arg}` ends before it starts ({end} < {start})"
        ));
    }
    Ok(FrameRange { start, end })
}
