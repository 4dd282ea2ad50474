//! Generated and engine WGSL checked with naga before a module is made: a
//! failure is an engine bug, reported with the module text's line.

/// Checks generated WGSL with naga first: a failure here is an engine bug (the
/// material shaders were checked on their own), reported with the module text's
/// line so it can be found in the log.
pub(crate) fn check(label: &str, wgsl: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(wgsl).map_err(|e| {
        format!(
            "{label}: generated WGSL does not parse: {}",
            e.emit_to_string(wgsl)
        )
    })?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| {
        format!(
            "{label}: generated WGSL is invalid: {}",
            crate::shader::wgsl_names::sanitize_in(&e.emit_to_string(wgsl), &module)
        )
    })?;
    Ok(())
}
