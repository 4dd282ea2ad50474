//! Frame sequences on disk: what an `-i` / `-o` argument names, the numbered files of an
//! input sequence, the names of the output files, `--frames` ranges, and the cleanup of
//! temporaries left by interrupted runs. No GPU code, no image decoding here.
//!
//! An argument is classified by [`SequenceSpec::parse`]:
//!
//! | argument | input | output |
//! |---|---|---|
//! | `-` | [`SequenceSpec::Stdin`] (a YUV4MPEG2 stream, see [`super::y4m`]) | [`SequenceSpec::Stdout`] |
//! | `in/%04d.png` (one `%d`, `%0Nd` or `%Nd`) | [`SequenceSpec::Pattern`] | [`SequenceSpec::Pattern`] |
//! | an existing folder | [`SequenceSpec::Dir`] | [`SequenceSpec::Dir`] (also a name ending in `/`) |
//! | a name with `*`, `?` or `[` that is not an existing file | [`SequenceSpec::Glob`] | — (literal name) |
//! | anything else | [`SequenceSpec::Single`] (one still image) | [`SequenceSpec::Single`] |
//!
//! Frame numbers are the numbers in the file names (never renumbered for patterns), so
//! `-i 'in/%04d.png' -o 'out/%04d.png'` writes `out/0017.png` from `in/0017.png`.

use std::fmt;
use std::fs;
use std::path::{Path, PathBuf};

use super::{FileFormat, IoError};

/// Which side of the command line an argument is for: `-` means stdin for an input and
/// stdout for an output, and wildcards only make sense for inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// An `-i` argument.
    Input,
    /// An `-o` argument.
    Output,
}

/// What an `-i` / `-o` argument names (see the module documentation for the rules).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SequenceSpec {
    /// A printf-style pattern with exactly one frame number conversion (`%d`, `%04d`,
    /// `%4d`) in the file name; `%%` is a literal `%`. Kept as written; see [`FramePattern`].
    Pattern { pattern: String },
    /// A folder: for an input, its image files (see [`InputSequence::open`]); for an
    /// output, files named by [`OutputPattern::in_dir`].
    Dir(PathBuf),
    /// A wildcard pattern (`*`, `?`, `[abc]`, `[a-z]`, `[!a-z]`) in the file name; the folder
    /// part is literal.
    Glob(String),
    /// `-` as an input: a YUV4MPEG2 stream on stdin.
    Stdin,
    /// `-` as an output: a YUV4MPEG2 stream on stdout.
    Stdout,
    /// One still image, not a sequence.
    Single(PathBuf),
}

impl SequenceSpec {
    /// Classify a command-line argument for `role`. Looks at the file system (whether the
    /// path is an existing folder or file) but never fails: problems in a pattern are
    /// reported by [`InputSequence::open`] / [`OutputPattern::new`].
    ///
    /// Precedence: `-`; then a pattern (any `%d`, `%0Nd` or `%Nd` conversion, even if a file
    /// of that literal name exists); then an existing folder; then, for inputs, an existing
    /// file (so a file whose name contains `[` stays openable), then wildcards; else a
    /// single image. For outputs a name ending in `/` is a folder (created when missing),
    /// and wildcard characters are literal.
    pub fn parse(arg: &str, role: Role) -> SequenceSpec {
        if arg == "-" {
            return match role {
                Role::Input => SequenceSpec::Stdin,
                Role::Output => SequenceSpec::Stdout,
            };
        }
        if has_conversion(arg) {
            return SequenceSpec::Pattern {
                pattern: arg.to_string(),
            };
        }
        let path = Path::new(arg);
        if path.is_dir() {
            return SequenceSpec::Dir(path.to_path_buf());
        }
        match role {
            Role::Input => {
                if !path.exists() && has_glob_chars(arg) {
                    SequenceSpec::Glob(arg.to_string())
                } else {
                    SequenceSpec::Single(path.to_path_buf())
                }
            }
            Role::Output => {
                if ends_with_separator(arg) {
                    SequenceSpec::Dir(path.to_path_buf())
                } else {
                    SequenceSpec::Single(path.to_path_buf())
                }
            }
        }
    }

    /// [`SequenceSpec::parse`] for an `-i` argument.
    pub fn parse_input(arg: &str) -> SequenceSpec {
        SequenceSpec::parse(arg, Role::Input)
    }

    /// [`SequenceSpec::parse`] for an `-o` argument.
    pub fn parse_output(arg: &str) -> SequenceSpec {
        SequenceSpec::parse(arg, Role::Output)
    }

    /// Whether this names a sequence of frames (everything but [`SequenceSpec::Single`]).
    pub fn is_sequence(&self) -> bool {
        !matches!(self, SequenceSpec::Single(_))
    }

    /// Whether this is a YUV4MPEG2 stream (stdin or stdout).
    pub fn is_stream(&self) -> bool {
        matches!(self, SequenceSpec::Stdin | SequenceSpec::Stdout)
    }

    /// The argument as a path, for error messages (`-` for the streams).
    pub fn display_path(&self) -> PathBuf {
        match self {
            SequenceSpec::Pattern { pattern } => PathBuf::from(pattern),
            SequenceSpec::Dir(p) | SequenceSpec::Single(p) => p.clone(),
            SequenceSpec::Glob(g) => PathBuf::from(g),
            SequenceSpec::Stdin | SequenceSpec::Stdout => PathBuf::from("-"),
        }
    }
}

fn ends_with_separator(s: &str) -> bool {
    s.ends_with('/') || (cfg!(windows) && s.ends_with('\\'))
}

fn is_separator(c: char) -> bool {
    c == '/' || (cfg!(windows) && c == '\\')
}

fn has_glob_chars(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

/// Whether `s` holds a frame number conversion (`%` followed by digits and `d`, not
/// escaped by `%%`).
fn has_conversion(s: &str) -> bool {
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            if b.get(i + 1) == Some(&b'%') {
                i += 2;
                continue;
            }
            let mut j = i + 1;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if b.get(j) == Some(&b'd') {
                return true;
            }
        }
        i += 1;
    }
    false
}

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
            let mut spec = String::new();
            while let Some(&(_, d)) = chars.peek() {
                if d.is_ascii_digit() {
                    spec.push(d);
                    chars.next();
                } else {
                    break;
                }
            }
            match chars.next() {
                Some((_, 'd')) => {}
                Some((_, other)) => {
                    return Err(format!(
                        "unsupported conversion `%{spec}{other}` (use %d, %04d or %4d; %% for a literal %)"
                    ))
                }
                None => {
                    return Err(format!(
                        "incomplete conversion `%{spec}` at the end (use %d, %04d or %4d; %% for a literal %)"
                    ))
                }
            }
            if padding.is_some() {
                return Err(
                    "more than one frame number conversion; use exactly one (%% for a literal %)"
                        .to_string(),
                );
            }
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
            padding = Some(match (width, zero) {
                (0 | 1, _) => Padding::None,
                (w, true) => Padding::Zeros(w),
                (w, false) => Padding::Spaces(w),
            });
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

/// The frames of an input sequence, sorted by frame number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputSequence {
    /// `(frame number, file)`, sorted by number, numbers distinct.
    pub frames: Vec<(u64, PathBuf)>,
}

impl InputSequence {
    /// List the frames an input argument names.
    ///
    /// - [`SequenceSpec::Pattern`]: the files of the pattern's folder whose names match it
    ///   exactly ([`FramePattern::match_file_name`]), numbered by their numbers. The
    ///   numbers need not start at 0 or 1 and may have gaps ([`InputSequence::gaps`]).
    /// - [`SequenceSpec::Dir`]: the folder's image files (an extension [`FileFormat`]
    ///   knows; hidden files skipped). When every name has a number (the last run of
    ///   digits in the name without its extension: `shot_0012.png` → 12) and no two
    ///   numbers are equal, those are the frame numbers; otherwise the files are sorted by
    ///   name and numbered 0, 1, 2...
    /// - [`SequenceSpec::Glob`]: the matching files (any extension; names starting with `.`
    ///   only when the pattern does), numbered as for a folder.
    /// - [`SequenceSpec::Single`]: one frame, number 0.
    ///
    /// Errors: [`IoError::Io`] (not found) when nothing matches or the folder is missing,
    /// [`IoError::Unsupported`] for a malformed pattern or for stdin/stdout (streams are
    /// read with [`super::y4m::Y4mReader`]).
    pub fn open(spec: &SequenceSpec) -> Result<InputSequence, IoError> {
        match spec {
            SequenceSpec::Pattern { pattern } => {
                let path = Path::new(pattern);
                let pat =
                    FramePattern::parse(pattern).map_err(|m| IoError::unsupported(path, m))?;
                let mut frames = Vec::new();
                for (name, _) in list_files(pat.dir())? {
                    if let Some(n) = pat.match_file_name(&name) {
                        frames.push((n, pat.format(n)));
                    }
                }
                if frames.is_empty() {
                    return Err(not_found(
                        path,
                        format!("no files match the pattern in {}", pat.dir().display()),
                    ));
                }
                frames.sort_by_key(|(n, _)| *n);
                Ok(InputSequence { frames })
            }
            SequenceSpec::Dir(dir) => {
                let files: Vec<(String, PathBuf)> = list_files(dir)?
                    .into_iter()
                    .filter(|(name, p)| {
                        !name.starts_with('.') && FileFormat::from_path(p).is_some()
                    })
                    .collect();
                if files.is_empty() {
                    return Err(not_found(
                        dir,
                        "the folder holds no image files".to_string(),
                    ));
                }
                Ok(InputSequence {
                    frames: number_files(files),
                })
            }
            SequenceSpec::Glob(glob) => {
                let path = Path::new(glob);
                let split = glob.rfind(is_separator).map(|i| i + 1).unwrap_or(0);
                let (dir_part, name_glob) = glob.split_at(split);
                if has_glob_chars(dir_part) {
                    return Err(IoError::unsupported(
                        path,
                        "wildcards are only supported in the file name, not in folder names",
                    ));
                }
                let glob_chars: Vec<char> = name_glob.chars().collect();
                check_glob(&glob_chars).map_err(|m| IoError::unsupported(path, m))?;
                let dir = if dir_part.is_empty() {
                    PathBuf::from(".")
                } else {
                    PathBuf::from(dir_part)
                };
                let files: Vec<(String, PathBuf)> = list_files(&dir)?
                    .into_iter()
                    .filter(|(name, _)| {
                        (!name.starts_with('.') || name_glob.starts_with('.'))
                            && glob_match(&glob_chars, &name.chars().collect::<Vec<_>>())
                    })
                    .map(|(name, _)| {
                        let p = PathBuf::from(format!("{dir_part}{name}"));
                        (name, p)
                    })
                    .collect();
                if files.is_empty() {
                    return Err(not_found(
                        path,
                        format!("no files match the wildcard pattern in {}", dir.display()),
                    ));
                }
                Ok(InputSequence {
                    frames: number_files(files),
                })
            }
            SequenceSpec::Single(p) => {
                let meta = fs::metadata(p).map_err(|e| IoError::io(p, e))?;
                if !meta.is_file() {
                    return Err(not_found(p, "not a file".to_string()));
                }
                Ok(InputSequence {
                    frames: vec![(0, p.clone())],
                })
            }
            SequenceSpec::Stdin | SequenceSpec::Stdout => Err(IoError::unsupported(
                Path::new("-"),
                "a stream is not a file sequence (read it as YUV4MPEG2)",
            )),
        }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no frames (never true for a sequence from [`InputSequence::open`]).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Lowest frame number.
    pub fn first_number(&self) -> Option<u64> {
        self.frames.first().map(|f| f.0)
    }

    /// Highest frame number.
    pub fn last_number(&self) -> Option<u64> {
        self.frames.last().map(|f| f.0)
    }

    /// The file of frame `n`, if present.
    pub fn path_of(&self, n: u64) -> Option<&Path> {
        self.frames
            .binary_search_by_key(&n, |f| f.0)
            .ok()
            .map(|i| self.frames[i].1.as_path())
    }

    /// The missing frame numbers between the first and the last frame, as inclusive
    /// ranges in increasing order (empty when the numbers are consecutive).
    pub fn gaps(&self) -> Vec<FrameRange> {
        self.frames
            .windows(2)
            .filter(|w| w[1].0 > w[0].0 + 1)
            .map(|w| FrameRange {
                start: w[0].0 + 1,
                end: w[1].0 - 1,
            })
            .collect()
    }

    /// The range with open ends resolved against this sequence (start at least the first
    /// frame number, end at most the last), or `None` when it selects no frame.
    pub fn resolve(&self, range: FrameRange) -> Option<FrameRange> {
        let (first, last) = (self.first_number()?, self.last_number()?);
        let r = FrameRange {
            start: range.start.max(first),
            end: range.end.min(last),
        };
        (r.start <= r.end && self.frames.iter().any(|f| r.contains(f.0))).then_some(r)
    }

    /// The frames whose numbers are in `range`. An error (for the user: it names the
    /// range and the sequence's numbers) when none are.
    pub fn slice(&self, range: FrameRange) -> Result<InputSequence, String> {
        let frames: Vec<(u64, PathBuf)> = self
            .frames
            .iter()
            .filter(|f| range.contains(f.0))
            .cloned()
            .collect();
        if frames.is_empty() {
            return Err(match (self.first_number(), self.last_number()) {
                (Some(a), Some(b)) => format!(
                    "--frames {range} selects no frames (the sequence has frames {a} to {b})"
                ),
                _ => format!("--frames {range} selects no frames (the sequence is empty)"),
            });
        }
        Ok(InputSequence { frames })
    }
}

fn not_found(path: &Path, message: String) -> IoError {
    IoError::io(
        path,
        std::io::Error::new(std::io::ErrorKind::NotFound, message),
    )
}

/// The regular files of a folder (symbolic links followed), as (UTF-8 name, path). Names
/// that are not UTF-8 are skipped.
fn list_files(dir: &Path) -> Result<Vec<(String, PathBuf)>, IoError> {
    let rd = fs::read_dir(dir).map_err(|e| IoError::io(dir, e))?;
    let mut out = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| IoError::io(dir, e))?;
        let Ok(name) = entry.file_name().into_string() else {
            continue;
        };
        let path = entry.path();
        // `fs::metadata` follows links; a dangling link is skipped.
        if fs::metadata(&path).map(|m| m.is_file()).unwrap_or(false) {
            out.push((name, path));
        }
    }
    Ok(out)
}

/// The number in a file name: the last run of ASCII digits before the extension.
fn number_in_name(name: &str) -> Option<u64> {
    let stem = Path::new(name).file_stem()?.to_str()?;
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end]
        .rfind(|c: char| !c.is_ascii_digit())
        .map(|i| i + 1)
        .unwrap_or(0);
    stem[start..end].parse().ok()
}

/// Number files by the numbers in their names when all have distinct ones, else by
/// position in name order.
fn number_files(mut files: Vec<(String, PathBuf)>) -> Vec<(u64, PathBuf)> {
    let numbers: Option<Vec<u64>> = files.iter().map(|(n, _)| number_in_name(n)).collect();
    if let Some(numbers) = numbers {
        let mut sorted = numbers.clone();
        sorted.sort_unstable();
        if sorted.windows(2).all(|w| w[0] != w[1]) {
            let mut frames: Vec<(u64, PathBuf)> = numbers
                .into_iter()
                .zip(files.into_iter().map(|f| f.1))
                .collect();
            frames.sort_by_key(|f| f.0);
            return frames;
        }
    }
    files.sort_by(|a, b| a.0.cmp(&b.0));
    files
        .into_iter()
        .enumerate()
        .map(|(i, (_, p))| (i as u64, p))
        .collect()
}

/// Check a wildcard pattern for an unclosed `[`.
fn check_glob(p: &[char]) -> Result<(), String> {
    let mut i = 0;
    while i < p.len() {
        if p[i] == '[' {
            match class_end(p, i) {
                Some(end) => i = end,
                None => return Err("unclosed `[` in the wildcard pattern".to_string()),
            }
        }
        i += 1;
    }
    Ok(())
}

/// Index of the `]` closing the class opened at `open` (a `]` right after `[`, `[!` or
/// `[^` is a member, as in the shell).
fn class_end(p: &[char], open: usize) -> Option<usize> {
    let mut j = open + 1;
    if matches!(p.get(j), Some('!' | '^')) {
        j += 1;
    }
    if p.get(j) == Some(&']') {
        j += 1;
    }
    while j < p.len() {
        if p[j] == ']' {
            return Some(j);
        }
        j += 1;
    }
    None
}

/// Whether `c` is in the class `p[open..=end]`.
fn class_matches(p: &[char], open: usize, end: usize, c: char) -> bool {
    let mut j = open + 1;
    let negate = matches!(p.get(j), Some('!' | '^'));
    if negate {
        j += 1;
    }
    let mut found = false;
    let mut first = true;
    while j < end {
        let lo = p[j];
        if !first && lo == ']' {
            break;
        }
        first = false;
        if j + 2 < end && p[j + 1] == '-' {
            let hi = p[j + 2];
            if lo <= c && c <= hi {
                found = true;
            }
            j += 3;
        } else {
            if lo == c {
                found = true;
            }
            j += 1;
        }
    }
    found != negate
}

/// Shell-style wildcard match of a whole file name: `*` (any run), `?` (one character),
/// `[abc]`, `[a-z]`, `[!a-z]` / `[^a-z]`. Iterative with backtracking to the last `*`, so
/// linear-ish and never exponential.
fn glob_match(p: &[char], s: &[char]) -> bool {
    let (mut pi, mut si) = (0usize, 0usize);
    let mut star: Option<(usize, usize)> = None;
    while si < s.len() {
        let step = match p.get(pi) {
            Some('*') => {
                star = Some((pi, si));
                pi += 1;
                continue;
            }
            Some('?') => Some(pi + 1),
            Some('[') => match class_end(p, pi) {
                Some(end) if class_matches(p, pi, end, s[si]) => Some(end + 1),
                Some(_) => None,
                None => (s[si] == '[').then_some(pi + 1),
            },
            Some(&c) => (c == s[si]).then_some(pi + 1),
            None => None,
        };
        match step {
            Some(next) => {
                pi = next;
                si += 1;
            }
            None => match star {
                Some((sp, ss)) => {
                    pi = sp + 1;
                    si = ss + 1;
                    star = Some((sp, ss + 1));
                }
                None => return false,
            },
        }
    }
    p[pi..].iter().all(|&c| c == '*')
}

/// Where the frames of an output sequence go.
///
/// - A pattern writes frame `n` to the pattern formatted with `n` (same padding as the
///   pattern: `out/%04d.png` → `out/0017.png`).
/// - A folder writes frame `n` to `DIR/NNNNNN.EXT`: the number zero-padded to
///   [`OutputPattern::DIR_DIGITS`] digits (more when larger), extension `png` unless
///   [`OutputPattern::in_dir`] says otherwise.
///
/// Frame numbers are those of the input (a sequence starting at 1001 writes `001001.png`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputPattern {
    pattern: FramePattern,
}

impl OutputPattern {
    /// Digits of the frame number in folder outputs.
    pub const DIR_DIGITS: usize = 6;
    /// Extension of folder outputs made by [`OutputPattern::new`].
    pub const DIR_EXTENSION: &'static str = "png";

    /// The output for an `-o` argument ([`SequenceSpec::Pattern`] or
    /// [`SequenceSpec::Dir`]), creating its folder (and parents) when missing.
    ///
    /// Errors: [`IoError::Unsupported`] for a malformed pattern, an unknown image
    /// extension, or a spec that is not a file sequence (single image, stdout, glob);
    /// [`IoError::Io`] when the folder cannot be created.
    pub fn new(spec: &SequenceSpec) -> Result<OutputPattern, IoError> {
        match spec {
            SequenceSpec::Pattern { pattern } => OutputPattern::from_pattern(pattern),
            SequenceSpec::Dir(dir) => OutputPattern::in_dir(dir, OutputPattern::DIR_EXTENSION),
            other => Err(IoError::unsupported(
                &other.display_path(),
                "the output of a sequence must be a pattern such as out/%04d.png or a folder",
            )),
        }
    }

    /// The output for a printf-style pattern (see [`FramePattern`]); creates its folder.
    pub fn from_pattern(pattern: &str) -> Result<OutputPattern, IoError> {
        let path = Path::new(pattern);
        let pat = FramePattern::parse(pattern).map_err(|m| IoError::unsupported(path, m))?;
        if FileFormat::from_path(&pat.format(0)).is_none() {
            return Err(IoError::unsupported(
                path,
                "unknown image file extension (use .png, .jpg, .exr, .tif, ...)",
            ));
        }
        fs::create_dir_all(pat.dir()).map_err(|e| IoError::io(pat.dir(), e))?;
        Ok(OutputPattern { pattern: pat })
    }

    /// The output `dir/NNNNNN.<extension>` (extension without the dot); creates `dir`.
    pub fn in_dir(dir: &Path, extension: &str) -> Result<OutputPattern, IoError> {
        if FileFormat::from_extension(extension).is_none() {
            return Err(IoError::unsupported(
                dir,
                format!("unknown image file extension `{extension}`"),
            ));
        }
        let dir_str = dir
            .to_str()
            .ok_or_else(|| IoError::unsupported(dir, "the folder name is not valid UTF-8"))?;
        let mut pattern = dir_str.replace('%', "%%");
        if !ends_with_separator(&pattern) {
            pattern.push(std::path::MAIN_SEPARATOR);
        }
        pattern.push_str(&format!(
            "%0{}d.{}",
            OutputPattern::DIR_DIGITS,
            extension.replace('%', "%%")
        ));
        let pat = FramePattern::parse(&pattern).map_err(|m| IoError::unsupported(dir, m))?;
        fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
        Ok(OutputPattern { pattern: pat })
    }

    /// The file frame `frame_number` is written to.
    pub fn path_for(&self, frame_number: u64) -> PathBuf {
        self.pattern.format(frame_number)
    }

    /// Whether the output of `frame_number` exists (for `--skip-existing`). Outputs are
    /// written atomically, so an existing file is a complete one.
    pub fn exists(&self, frame_number: u64) -> bool {
        fs::symlink_metadata(self.path_for(frame_number)).is_ok()
    }

    /// The folder the outputs go to.
    pub fn dir(&self) -> &Path {
        self.pattern.dir()
    }

    /// The underlying pattern.
    pub fn pattern(&self) -> &FramePattern {
        &self.pattern
    }
}

/// The process id in the name of a temporary made by [`super::write_atomic`]
/// (`.NAME.fxtmp-<pid>-<n>`, NAME non-empty, pid and n decimal), or `None` for any other
/// name.
pub fn atomic_temporary_pid(file_name: &str) -> Option<u32> {
    let rest = file_name.strip_prefix('.')?;
    let at = rest.rfind(".fxtmp-")?;
    if at == 0 {
        return None;
    }
    let (pid, n) = rest[at + ".fxtmp-".len()..].split_once('-')?;
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    if !digits(pid) || !digits(n) {
        return None;
    }
    n.parse::<u64>().ok()?;
    pid.parse().ok()
}

/// Whether a process with this id runs on this machine, as far as we can tell: on Linux
/// via `/proc/<pid>`; elsewhere (or without `/proc`) every other process counts as gone.
fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = Path::new("/proc");
    cfg!(target_os = "linux")
        && proc_root.join("self").exists()
        && proc_root.join(pid.to_string()).exists()
}

/// Delete the temporaries that [`super::write_atomic`] leaves in `dir` when a process is
/// killed mid-write: regular files named exactly `.NAME.fxtmp-<pid>-<n>` (see
/// [`atomic_temporary_pid`]) whose process is no longer running (ours and, on Linux, any
/// other live process's are kept, so a concurrent run writing into the same folder is not
/// disturbed; a process on another machine sharing the folder is not seen). Nothing else
/// is touched, and subfolders are not visited. Returns the removed paths.
pub fn remove_stale_temporaries(dir: &Path) -> Result<Vec<PathBuf>, IoError> {
    let rd = fs::read_dir(dir).map_err(|e| IoError::io(dir, e))?;
    let mut removed = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| IoError::io(dir, e))?;
        let Ok(name) = entry.file_name().into_string() else {
            continue;
        };
        let Some(pid) = atomic_temporary_pid(&name) else {
            continue;
        };
        if process_alive(pid) {
            continue;
        }
        let path = entry.path();
        let is_file = fs::symlink_metadata(&path)
            .map(|m| m.file_type().is_file())
            .unwrap_or(false);
        if !is_file {
            continue;
        }
        match fs::remove_file(&path) {
            Ok(()) => removed.push(path),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(IoError::io(&path, e)),
        }
    }
    removed.sort();
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(p: &str, s: &str) -> bool {
        let p: Vec<char> = p.chars().collect();
        let s: Vec<char> = s.chars().collect();
        glob_match(&p, &s)
    }

    #[test]
    fn glob_matching() {
        assert!(m("*.png", "a.png"));
        assert!(m("*.png", ".png"));
        assert!(!m("*.png", "a.jpg"));
        assert!(m("f??.png", "f01.png"));
        assert!(!m("f??.png", "f1.png"));
        assert!(m("f[0-9][abc].png", "f3b.png"));
        assert!(!m("f[0-9][abc].png", "f3d.png"));
        assert!(m("f[!0-9]*", "fx12"));
        assert!(!m("f[^0-9]*", "f12"));
        assert!(m("[]]x", "]x"));
        assert!(m("a*b*c", "aXbYbZc"));
        assert!(!m("a*b*c", "aXbYbZ"));
        assert!(m("**", ""));
        assert!(m(
            "*a*a*a*a*a*a*b",
            "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaab"
        ));
        assert!(!m(
            "*a*a*a*a*a*a*b",
            "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"
        ));
    }

    #[test]
    fn numbers_in_names() {
        assert_eq!(number_in_name("f000.png"), Some(0));
        assert_eq!(number_in_name("shot3_0012.png"), Some(12));
        assert_eq!(number_in_name("x.png"), None);
        assert_eq!(number_in_name("12"), Some(12));
    }

    #[test]
    fn temporary_names() {
        assert_eq!(atomic_temporary_pid(".out.png.fxtmp-123-4"), Some(123));
        assert_eq!(atomic_temporary_pid(".a.fxtmp-1-0"), Some(1));
        assert_eq!(atomic_temporary_pid("out.png.fxtmp-123-4"), None);
        assert_eq!(atomic_temporary_pid("..fxtmp-1-2"), None);
        assert_eq!(atomic_temporary_pid(".fxtmp-1-2"), None);
        assert_eq!(atomic_temporary_pid(".a.fxtmp-1-"), None);
        assert_eq!(atomic_temporary_pid(".a.fxtmp-1-2x"), None);
        assert_eq!(atomic_temporary_pid(".a.fxtmp-1"), None);
        assert_eq!(atomic_temporary_pid(".a.fxtmp-x-1"), None);
    }
}
