//! Input sequences: the frames of a pattern, a folder or a wildcard pattern, numbered.

use super::*;
use std::fs;

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
            SequenceSpec::Pattern { pattern } => open_pattern(pattern),
            SequenceSpec::Dir(dir) => open_dir(dir),
            SequenceSpec::Glob(glob) => open_glob(glob),
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
            SequenceSpec::Y4m(p) | SequenceSpec::Video(p) => Err(IoError::unsupported(
                p,
                "a y4m or video file is a stream, not a file sequence",
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

/// The files a `%04d` / `####` pattern matches, by number.
fn open_pattern(pattern: &str) -> Result<InputSequence, IoError> {
    let path = Path::new(pattern);
    let pat = FramePattern::parse(pattern).map_err(|m| IoError::unsupported(path, m))?;
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

/// The image files of a folder (hidden files skipped), numbered.
fn open_dir(dir: &Path) -> Result<InputSequence, IoError> {
    let files: Vec<(String, PathBuf)> = list_files(dir)?
        .into_iter()
        .filter(|(name, p)| !name.starts_with('.') && FileFormat::from_path(p).is_some())
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

/// The files a wildcard pattern (`*`, `?`, `[...]` in the file name) matches, numbered.
fn open_glob(glob: &str) -> Result<InputSequence, IoError> {
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

fn not_found(path: &Path, message: String) -> IoError {
    IoError::io(
        path,
        std::io::Error::new(std::io::ErrorKind::NotFound, message),
    )
}

/// The regular files of a folder (symbolic links followed), as (UTF-8 name, path). Names
/// that are not UTF-8 are skipped.
fn list_files(dir: &Path) -> Result<Vec<(String, PathBuf)>, IoError> {
    let mut out = Vec::new();
    for entry in named_entries(dir)? {
        let (name, path) = entry?;
        // `fs::metadata` follows links; a dangling link is skipped.
        if fs::metadata(&path).map(|m| m.is_file()).unwrap_or(false) {
            out.push((name, path));
        }
    }
    Ok(out)
}

/// The number in a file name: the last run of ASCII digits before the extension.
pub(super) fn number_in_name(name: &str) -> Option<u64> {
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
