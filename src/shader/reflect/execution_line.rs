//! The `// @execution(compute)` line of a pass shader (docs/shaders.md,
//! "Compute passes"): its `@compute` entry point runs under compute execution
//! only, and fragment execution draws its `@fragment` one.

use super::ComputeNative;
use crate::script::{Diagnostic, FileId, Span};

/// The line that keeps a shader's `@compute` entry point to compute execution.
const COMPUTE_EXECUTION_ONLY: &str = "// @execution(compute)";

/// Whether `wgsl` has the `// @execution(compute)` line; an error where it has
/// no fragment entry point to draw under fragment execution.
pub(super) fn compute_execution_only(
    wgsl: &str,
    file: FileId,
    native: &ComputeNative,
) -> Result<bool, Diagnostic> {
    let Some((off, line)) = crate::shader::preprocess::lines_with_offsets(wgsl)
        .find(|(_, l)| l.trim() == COMPUTE_EXECUTION_ONLY)
    else {
        return Ok(false);
    };
    if native.fragment.is_none() {
        let at = Span::new(file, off, off + line.trim_end().len());
        return Err(Diagnostic::error(
            "`// @execution(compute)` keeps the `@compute` entry point to compute execution, but the shader has no `@fragment` entry point to draw under fragment execution",
        )
        .at(at, "add a `@fragment` entry point or remove this line"));
    }
    Ok(true)
}
