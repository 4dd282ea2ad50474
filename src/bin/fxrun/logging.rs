//! fxrun's log: the `log` crate's lines of the library and the program on
//! stderr, worded like fxrun's own messages.

use std::io::Write as _;

/// The log filter unless `RUST_LOG` says otherwise: fxgraph's and fxrun's own
/// warnings only; the dependencies' log lines (naga's validation errors, wgpu's,
/// png's, ...) would interleave with the diagnostics that already report the same
/// problems, so they are shown with `-v` only (warnings and errors).
fn log_filter(verbose: bool) -> &'static str {
    if verbose {
        "warn,fxgraph=info,fxrun=info,wgpu_hal::gles::egl=off,winit=error"
    } else {
        "off,fxgraph=warn,fxrun=warn"
    }
}

/// Sets up the logger: [`log_filter`] unless `RUST_LOG` is set.
pub(crate) fn init(verbose: bool) {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or(log_filter(verbose)),
    )
    // Warnings read like fxrun's own (`fxrun: warning: ...`); RUST_LOG=debug lines
    // name their module.
    .format(|buf, record| {
        let msg = record.args().to_string();
        match record.level() {
            // Rendered diagnostics carry their own `path:line:col: warning:`.
            log::Level::Warn if msg.contains(": warning:") => writeln!(buf, "{msg}"),
            log::Level::Error => writeln!(buf, "fxrun: error: {msg}"),
            log::Level::Warn => writeln!(buf, "fxrun: warning: {msg}"),
            level => writeln!(buf, "fxrun: {level} {}: {msg}", record.target()),
        }
    })
    .init();
}
