//! Where effect scripts come from, as a trait: the lookup policy (files on disk,
//! search folders, `INCLUDE` confinement) belongs to the caller, so the graph layer
//! reads no file. [`Builtins`] serves the embedded library alone;
//! `fxgraph::lookup::DiskEffects` adds files on disk as `fxrun` finds them.

use super::library::embedded_effect;
use std::path::PathBuf;

/// Where a loaded file came from.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// A file on disk (as found; its folder is where its shaders are looked up).
    Disk(PathBuf),
    /// A file of the embedded library, by file name (`glow.fx`).
    Embedded(String),
}

/// A script found by an [`EffectSource`].
#[derive(Debug, Clone)]
pub struct Found {
    pub origin: Origin,
    /// How the file is named in messages.
    pub shown: String,
    pub text: String,
    /// Identity for include-once: a canonical path, or `<builtin>/NAME.fx`.
    pub key: String,
}

impl Found {
    /// An embedded library file, if there is one of that name.
    pub fn embedded(file: &str) -> Option<Found> {
        Some(Found {
            origin: Origin::Embedded(file.to_string()),
            shown: format!("<builtin>/effects/{file}"),
            text: embedded_effect(file)?.to_string(),
            key: format!("<builtin>/{file}"),
        })
    }
}

/// Why an `INCLUDE` was not served.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum IncludeError {
    /// Refused by the confinement rules; the file was not read. The message
    /// completes "cannot include `TARGET`: ...".
    Refused(String),
    /// Nowhere to be found.
    NotFound,
}

/// The lookup policy for effect scripts.
pub trait EffectSource: std::fmt::Debug + Send + Sync {
    /// An effect named on the command line: a path to a file, or a name. `Ok(None)`
    /// when nothing has that name; `Err` (a message) when a file exists but cannot
    /// be read.
    fn entry(&self, arg: &str) -> Result<Option<Found>, String>;
    /// `NAME.fx` for an effect a script instantiates by name (`EFFECT.NAME`) that is
    /// not loaded yet.
    fn named(&self, name: &str) -> Result<Option<Found>, String>;
    /// `INCLUDE "target"` in the file that came from `from`.
    fn include(&self, from: &Origin, target: &str) -> Result<Found, IncludeError>;
}

/// The embedded library only: names, and `INCLUDE`s of library files by name.
/// Reads no file; the default of a [`CompileRequest`](super::CompileRequest).
#[derive(Debug, Clone, Copy, Default)]
pub struct Builtins;

impl EffectSource for Builtins {
    fn entry(&self, arg: &str) -> Result<Option<Found>, String> {
        if arg.ends_with(".fx") || arg.contains(['/', '\\']) {
            return Err(
                "this compilation reads no files (its source is the built-in library; give it fxgraph::lookup::DiskEffects)"
                    .into(),
            );
        }
        Ok(Found::embedded(&format!("{arg}.fx")))
    }

    fn named(&self, name: &str) -> Result<Option<Found>, String> {
        Ok(Found::embedded(&format!("{name}.fx")))
    }

    fn include(&self, _from: &Origin, target: &str) -> Result<Found, IncludeError> {
        if target.contains(['/', '\\']) {
            return Err(IncludeError::Refused(
                "the built-in library has no folders".into(),
            ));
        }
        Found::embedded(target).ok_or(IncludeError::NotFound)
    }
}
