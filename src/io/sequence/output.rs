//! Output patterns, and cleaning up the temporaries of interrupted writes.

use super::*;
use std::fs;

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
                "the output of a sequence must be a pattern such as out/%04d.png, a folder, a .y4m or video file, or - (y4m on stdout)",
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
/// name (a video encoder's temporary, `.NAME.fxtmp-<pid>-<n>.EXT`, is not one).
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
    let mut removed = Vec::new();
    for entry in named_entries(dir)? {
        let (name, path) = entry?;
        let Some(pid) = atomic_temporary_pid(&name) else {
            continue;
        };
        if process_alive(pid) {
            continue;
        }
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
