//! The viewer's commands: what a key, a button of the panel or a scripted
//! `key` action asks for. The window loop maps keys to them and runs them.

/// A command of a key (or of the panel's buttons).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Next image, or next frame (pauses a sequence).
    Next,
    /// Previous image or frame.
    Prev,
    /// First image or frame.
    First,
    PlayPause,
    Fit,
    OneToOne,
    ZoomIn,
    ZoomOut,
    TogglePanel,
    ToggleSplit,
    Screenshot,
    /// Back to the run's camera (scenes).
    CameraHome,
    /// Inspect the next / previous pass of the list.
    InspectNext,
    InspectPrev,
    Quit,
}

impl Command {
    /// Does holding the key repeat it?
    pub fn repeats(self) -> bool {
        matches!(
            self,
            Command::Next | Command::Prev | Command::ZoomIn | Command::ZoomOut
        )
    }
}
