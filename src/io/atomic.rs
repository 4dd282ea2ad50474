//! Atomic writes: a temporary file in the same folder, fsynced and renamed; and the
//! [`OutputTarget`]s a stream of frames is written into (a file made final only when
//! the job completes, stdout).

use super::*;
use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// A byte stream one output is written into (a y4m file, stdout, a video encoder's
/// input), made final only when the job completes.
pub trait OutputTarget: Write + Send {
    /// The job completed: flush, and make the output final (a file: rename it into
    /// place; an encoder: wait for it to finish its file).
    fn commit(&mut self) -> Result<(), IoError>;
    /// The job failed or was interrupted: discard the output where it can be (a file's
    /// temporary is removed, an existing file at the path is untouched); a pipe keeps
    /// what was written (flushed).
    fn abandon(&mut self);
}

/// Standard output: what is written stays; both ends flush.
impl OutputTarget for BufWriter<std::io::Stdout> {
    fn commit(&mut self) -> Result<(), IoError> {
        self.flush()
            .map_err(|e| IoError::io(Path::new("stdout"), e))
    }
    fn abandon(&mut self) {
        let _ = self.flush();
    }
}

/// A new temporary file next to `path` (`.NAME.fxtmp-<pid>-<n>`, with `.EXT` added
/// when `extension` is given, for programs that choose the format by the name), created
/// empty so that the name is ours. Its folder is `path`'s.
pub fn create_temporary(path: &Path, extension: Option<&str>) -> Result<(PathBuf, File), IoError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        IoError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
        )
    })?;
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    let pid = std::process::id();
    let ext = extension.map(|e| format!(".{e}")).unwrap_or_default();
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let file = format!(".{}.fxtmp-{pid}-{n}{ext}", name.to_string_lossy());
        let tmp = match dir {
            Some(d) => d.join(file),
            None => PathBuf::from(file),
        };
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(IoError::io(path, e)),
        }
    }
}

/// Rename a finished temporary over `path` and make the rename durable (best effort).
pub fn rename_into_place(tmp: &Path, path: &Path) -> Result<(), IoError> {
    fs::rename(tmp, path).map_err(|e| IoError::io(path, e))?;
    #[cfg(unix)]
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// A file written atomically: the bytes go to a temporary in the same folder
/// ([`create_temporary`]), which [`OutputTarget::commit`] flushes, fsyncs and renames
/// over the path; [`OutputTarget::abandon`] or dropping it uncommitted removes the
/// temporary, so an existing file at the path is untouched. A device or a pipe
/// (`/dev/null`, a FIFO) is written in place: it cannot be replaced by a rename.
pub struct AtomicFile {
    path: PathBuf,
    /// The temporary (`None` when writing a device in place, or once finished).
    tmp: Option<PathBuf>,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Start writing `path`.
    pub fn create(path: &Path) -> Result<AtomicFile, IoError> {
        if let Ok(m) = fs::metadata(path) {
            if !m.is_file() && !m.is_dir() {
                let file = OpenOptions::new()
                    .write(true)
                    .open(path)
                    .map_err(|e| IoError::io(path, e))?;
                return Ok(AtomicFile {
                    path: path.to_path_buf(),
                    tmp: None,
                    out: Some(BufWriter::with_capacity(1 << 20, file)),
                });
            }
        }
        let (tmp, file) = create_temporary(path, None)?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp: Some(tmp),
            out: Some(BufWriter::with_capacity(1 << 20, file)),
        })
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The buffered writer of the temporary.
    pub fn writer(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        self.out
            .as_mut()
            .ok_or_else(|| std::io::Error::other("the file is already finished"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer()?.write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.writer()?.write_all(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.writer()?.flush()
    }
}

impl OutputTarget for AtomicFile {
    fn commit(&mut self) -> Result<(), IoError> {
        let path = self.path.clone();
        let out = self
            .out
            .take()
            .ok_or_else(|| IoError::io(&path, std::io::Error::other("already finished")))?;
        let file = out
            .into_inner()
            .map_err(|e| IoError::io(&path, e.into_error()))?;
        let Some(tmp) = self.tmp.clone() else {
            return Ok(()); // a device, written in place
        };
        file.sync_all().map_err(|e| IoError::io(&path, e))?;
        drop(file);
        rename_into_place(&tmp, &path)?;
        self.tmp = None;
        Ok(())
    }
    fn abandon(&mut self) {
        self.out = None;
        if let Some(tmp) = self.tmp.take() {
            let _ = fs::remove_file(tmp);
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        self.abandon();
    }
}

/// Write a file atomically: `f` writes into a temporary file in the same folder
/// (`.name.fxtmp-<pid>-<n>`), which is flushed, fsynced and renamed over `path`.
/// On any error (or a panic in `f`) the temporary is removed and an existing file at
/// `path` is untouched.
pub fn write_atomic(
    path: &Path,
    f: impl FnOnce(&mut BufWriter<File>) -> Result<(), IoError>,
) -> Result<(), IoError> {
    let mut file = AtomicFile::create(path)?;
    f(file.writer().map_err(|e| IoError::io(path, e))?)?;
    file.commit()
}
