//! Frame sequences on disk: what an `-i` / `-o` argument names, the numbered files of an
//! input sequence, the names of the output files, `--frames` ranges, and the cleanup of
//! temporaries left by interrupted runs. No GPU code, no image decoding here.
//!
//! An argument is classified by [`SequenceSpec::parse`]:
//!
//! | argument | input | output |
//! |---|---|---|
//! | `-` | [`SequenceSpec::Stdin`] (a YUV4MPEG2 stream, see [`super::y4m`]) | [`SequenceSpec::Stdout`] |
//! | a `.y4m` file | [`SequenceSpec::Y4m`] | [`SequenceSpec::Y4m`] |
//! | a video file (`.mp4`, `.mkv`, ...: [`super::video::is_video_path`]) | [`SequenceSpec::Video`] | [`SequenceSpec::Video`] |
//! | `in/%04d.png` (one `%d`, `%0Nd` or `%Nd`) | [`SequenceSpec::Pattern`] | [`SequenceSpec::Pattern`] |
//! | an existing folder | [`SequenceSpec::Dir`] | [`SequenceSpec::Dir`] (also a name ending in `/`) |
//! | a name with `*`, `?` or `[` that is not an existing file | [`SequenceSpec::Glob`] | — (literal name) |
//! | anything else | [`SequenceSpec::Single`] (one still image) | [`SequenceSpec::Single`] |
//!
//! Frame numbers are the numbers in the file names (never renumbered for patterns), so
//! `-i 'in/%04d.png' -o 'out/%04d.png'` writes `out/0017.png` from `in/0017.png`.

use std::path::{Path, PathBuf};

use super::{FileFormat, IoError};

mod glob;
mod input;
mod output;
mod pattern;

use glob::{check_glob, glob_match};
#[cfg(test)]
use input::number_in_name;
pub use input::InputSequence;
pub use output::{atomic_temporary_pid, remove_stale_temporaries, OutputPattern};
pub use pattern::{parse_frames, FramePattern, FrameRange, Padding};

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
    /// A YUV4MPEG2 file (`.y4m`): a stream with a name.
    Y4m(PathBuf),
    /// A video container file (`.mp4`, `.mkv`, ...), read and written through ffmpeg
    /// ([`super::video`]).
    Video(PathBuf),
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
        if is_y4m_path(path) {
            return SequenceSpec::Y4m(path.to_path_buf());
        }
        if super::video::is_video_path(path) {
            return SequenceSpec::Video(path.to_path_buf());
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

    /// Whether this is a stream of frames in one pipe or file: YUV4MPEG2 on stdin or
    /// stdout, a `.y4m` file, a video file.
    pub fn is_stream(&self) -> bool {
        matches!(
            self,
            SequenceSpec::Stdin
                | SequenceSpec::Stdout
                | SequenceSpec::Y4m(_)
                | SequenceSpec::Video(_)
        )
    }

    /// The argument as a path, for error messages (`-` for the streams).
    pub fn display_path(&self) -> PathBuf {
        match self {
            SequenceSpec::Pattern { pattern } => PathBuf::from(pattern),
            SequenceSpec::Dir(p)
            | SequenceSpec::Single(p)
            | SequenceSpec::Y4m(p)
            | SequenceSpec::Video(p) => p.clone(),
            SequenceSpec::Glob(g) => PathBuf::from(g),
            SequenceSpec::Stdin | SequenceSpec::Stdout => PathBuf::from("-"),
        }
    }
}

/// Whether `p` names a YUV4MPEG2 file (extension `.y4m`, any case).
pub fn is_y4m_path(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("y4m"))
}

/// The entries of folder `dir` whose names are UTF-8, as (name, path), read as the
/// iterator goes (other names are skipped).
fn named_entries(
    dir: &Path,
) -> Result<impl Iterator<Item = Result<(String, PathBuf), IoError>> + '_, IoError> {
    let rd = std::fs::read_dir(dir).map_err(|e| IoError::io(dir, e))?;
    Ok(rd.filter_map(move |entry| match entry {
        Err(e) => Some(Err(IoError::io(dir, e))),
        Ok(entry) => {
            let name = entry.file_name().into_string().ok()?;
            Some(Ok((name, entry.path())))
        }
    }))
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
