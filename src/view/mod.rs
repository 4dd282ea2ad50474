//! The reusable parts of `fxrun --view` (feature `view`), for an application
//! that shows effects in its own window: everything here uses the library's
//! public API and wgpu, no window system. The viewer's parameter model is
//! [`crate::app::Effect::set`].
//!
//! - [`present`]: the image pass ([`present::Presenter`]): a texture drawn into
//!   a window's surface, fitted, with exposure, a split view, false colours for
//!   one-channel and vector images (`shaders/view/present.wgsl`).
//! - [`inspect`]: the pass list of a prepared effect ([`inspect::pass_rows`]) and
//!   what is inspected (a pass, the output, the input, an AUX image), with the
//!   value ranges that shade it.
//! - [`camera_control`]: orbit, pan, dolly and fly of a scene camera
//!   ([`camera_control::CameraControl`]).
//! - [`panel_cache`]: an egui panel drawn into a texture once and reused while
//!   nothing changes ([`panel_cache::PanelCache`]).

pub mod camera_control;
pub mod inspect;
pub mod panel_cache;
pub mod present;
