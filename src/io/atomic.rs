//! Atomic writes: a temporary file in the same folder, fsynced and renamed.

use super::*;
use std::fs::{self, File, OpenOptions};
use std::io::BufWriter;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Removes the temporary file unless disarmed.
struct TempGuard<'a> {
    path: Option<&'a Path>,
}

impl Drop for TempGuard<'_> {
    fn drop(&mut self) {
        if let Some(p) = self.path {
            let _ = fs::remove_file(p);
        }
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
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        IoError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
        )
    })?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // A device or a pipe (`/dev/null`, `/dev/full`, a FIFO) is written in place: it
    // cannot be replaced by a rename, and its write errors must still be reported.
    if let Ok(m) = fs::metadata(path) {
        if !m.is_file() && !m.is_dir() {
            let file = OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(|e| IoError::io(path, e))?;
            let mut out = BufWriter::with_capacity(1 << 20, file);
            f(&mut out)?;
            out.into_inner()
                .map_err(|e| IoError::io(path, e.into_error()))?;
            return Ok(());
        }
    }
    let pid = std::process::id();
    let (tmp, file) = loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{}.fxtmp-{pid}-{n}", name.to_string_lossy()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => break (tmp, file),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(IoError::io(path, e)),
        }
    };
    let mut guard = TempGuard { path: Some(&tmp) };
    let mut out = BufWriter::with_capacity(1 << 20, file);
    f(&mut out)?;
    let file = out
        .into_inner()
        .map_err(|e| IoError::io(path, e.into_error()))?;
    file.sync_all().map_err(|e| IoError::io(path, e))?;
    drop(file);
    fs::rename(&tmp, path).map_err(|e| IoError::io(path, e))?;
    guard.path = None;
    // Make the rename itself durable (best effort; not possible on every platform).
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}
