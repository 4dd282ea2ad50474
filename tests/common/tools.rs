//! Running the reference tools of the tests (ffmpeg, ffprobe, ImageMagick's
//! `import`): a tool that cannot start or that fails stops the test with its
//! stderr.

use std::process::{Command, Output};

/// Runs `cmd`, the reference tool `what` (`start` says what to run and how to get
/// it): its output; panics when it cannot start or fails, showing its stderr.
pub fn checked(cmd: &mut Command, what: &str, start: &str) -> Output {
    let o = cmd.output().expect(start);
    assert!(
        o.status.success(),
        "{what} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}
