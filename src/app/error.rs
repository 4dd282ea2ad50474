//! The error of an application job, and whether the input or the system is to blame.

use crate::gpu::context::GpuError;
use crate::gpu::executor::ExecError;
use crate::io::IoError;

/// Errors of a run. [`RunError::is_input_error`] tells the caller's input (the
/// effect, a file, an argument) from a fault of the system (I/O, GPU, internal);
/// what that means for an exit status is the application's business.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The effect, its shaders or a `--set` were rejected (diagnostics rendered).
    #[error("{rendered}")]
    Rejected { rendered: String },
    /// An input file was rejected (corrupt, unsupported).
    #[error(transparent)]
    BadInput(IoError),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(IoError),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("{0}")]
    Other(String),
}

impl RunError {
    /// True when the input was rejected (the effect, its shaders, a `--set`, an
    /// image file); false for I/O, GPU and internal faults.
    pub fn is_input_error(&self) -> bool {
        match self {
            RunError::Rejected { .. } | RunError::BadInput(_) => true,
            RunError::Io(_) | RunError::Gpu(_) | RunError::Other(_) => false,
        }
    }
}

/// Errors of running a prepared effect (its diagnostics were reported when it
/// was prepared, so a rejection here is internal).
impl From<ExecError> for RunError {
    fn from(e: ExecError) -> Self {
        match e {
            ExecError::Gpu(g) => RunError::Gpu(g),
            ExecError::Rejected(d) => RunError::Other(format!(
                "{} error(s) in the effect or its shaders",
                d.error_count()
            )),
            ExecError::Input(s) => RunError::Other(s),
        }
    }
}

impl From<IoError> for RunError {
    fn from(e: IoError) -> Self {
        if e.is_input_error() {
            RunError::BadInput(e)
        } else {
            RunError::Io(e)
        }
    }
}
