//! Finding effect scripts on disk, as `fxrun` does: the lookup policy the graph
//! layer leaves to its caller ([`EffectSource`]).
//!
//! - An effect given as a path (`my.fx`, `dir/x`, or any existing file) is read from
//!   that path: a regular file (not a device or a pipe) of at most
//!   [`MAX_INCLUDE_BYTES`].
//! - An effect given by name, or instantiated by name in a script (`EFFECT.NAME`), is
//!   `NAME.fx` in the search folders (in order), then `./NAME.fx`, then
//!   `./effects/NAME.fx`, then the embedded library. A file on disk named like a
//!   built-in effect overrides it (logged).
//! - `INCLUDE "file.fx"` is a path relative to the including file's folder, confined
//!   to it (no `..`, no absolute path, symbolic links resolved and checked, a
//!   regular file of at most [`MAX_INCLUDE_BYTES`]), or a file of the built-in
//!   library. A refused file is never read.

use crate::graph::library::embedded_effect;
use crate::graph::source::{EffectSource, Found, IncludeError, Origin};
use crate::graph::CompileRequest;
use crate::shader::include::{check_relative, read_confined, RealFs, MAX_INCLUDE_BYTES};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Effect files on disk, then the embedded library.
#[derive(Debug, Clone, Default)]
pub struct DiskEffects {
    /// Folders searched for `NAME.fx` before `.`, `./effects` and the embedded
    /// library.
    pub search_dirs: Vec<PathBuf>,
}

impl DiskEffects {
    /// A compilation of `effects` (paths or names) that reads them from disk.
    pub fn request(effects: &[String], overrides: &[String]) -> CompileRequest {
        DiskEffects::request_with(effects, crate::graph::Override::parse_all(overrides))
    }

    /// [`DiskEffects::request`] with overrides parsed already.
    pub fn request_with(
        effects: &[String],
        overrides: Vec<crate::graph::Override>,
    ) -> CompileRequest {
        CompileRequest {
            effects: effects.to_vec(),
            overrides,
            source: Some(Arc::new(DiskEffects::default())),
        }
    }

    fn found_on_disk(path: &Path, shown: String) -> Result<Found, String> {
        let text = read_effect_file(path).map_err(|e| e.to_string())?;
        let key = std::fs::canonicalize(path)
            .unwrap_or(path.to_path_buf())
            .display()
            .to_string();
        Ok(Found {
            origin: Origin::Disk(path.to_path_buf()),
            shown,
            text,
            key,
        })
    }
}

impl EffectSource for DiskEffects {
    fn entry(&self, arg: &str) -> Result<Option<Found>, String> {
        let path = Path::new(arg);
        // A RetroArch preset, lowered to an effect file (docs/slang.md).
        #[cfg(feature = "slang")]
        if crate::slang::is_preset(arg) {
            let lowered = crate::slang::lower_preset(path).map_err(|e| e.to_string())?;
            return DiskEffects::found_on_disk(&lowered.fx, arg.to_string()).map(Some);
        }
        let as_file = path.extension().is_some_and(|e| e == "fx") || path.components().count() > 1;
        if as_file || path.is_file() {
            return DiskEffects::found_on_disk(path, arg.to_string()).map(Some);
        }
        self.named(arg)
    }

    fn named(&self, name: &str) -> Result<Option<Found>, String> {
        let file = format!("{name}.fx");
        let mut dirs = self.search_dirs.clone();
        dirs.push(PathBuf::from("."));
        dirs.push(PathBuf::from("effects"));
        for dir in dirs {
            let p = dir.join(&file);
            if !p.is_file() {
                continue;
            }
            let shown = p.display().to_string();
            if embedded_effect(&file).is_some() {
                log::info!("{shown} overrides the built-in effect `{name}`");
            }
            return DiskEffects::found_on_disk(&p, shown)
                .map(Some)
                .map_err(|e| format!("{}: {e}", p.display()));
        }
        Ok(Found::embedded(&file))
    }

    fn include(&self, from: &Origin, target: &str) -> Result<Found, IncludeError> {
        let parts = check_relative(target).map_err(IncludeError::Refused)?;
        if let Origin::Disk(p) = from {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            if let Ok(dir_canon) = std::fs::canonicalize(dir) {
                match read_confined(&dir_canon, &parts, &RealFs) {
                    Ok(Some((canon, text))) => {
                        let shown = dir
                            .join(parts.iter().collect::<PathBuf>())
                            .display()
                            .to_string();
                        return Ok(Found {
                            key: canon.display().to_string(),
                            origin: Origin::Disk(canon),
                            shown,
                            text,
                        });
                    }
                    Ok(None) => {}
                    Err(m) => return Err(IncludeError::Refused(m.replace("{path}", target))),
                }
            }
        }
        let file = Path::new(target)
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or(target);
        Found::embedded(file).ok_or(IncludeError::NotFound)
    }
}

/// Read an effect file given on the command line: a regular file (not a device or a
/// pipe) of at most [`MAX_INCLUDE_BYTES`].
fn read_effect_file(path: &Path) -> std::io::Result<String> {
    use std::io::Read as _;
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let too_big = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("larger than {} KiB", MAX_INCLUDE_BYTES / 1024),
        )
    };
    if meta.len() > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(MAX_INCLUDE_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_INCLUDE_BYTES {
        return Err(too_big());
    }
    Ok(text)
}
