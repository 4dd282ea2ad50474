//! The reusable parts of `fxrun --view` (feature `view`), for an application
//! that shows effects in its own window: everything here uses the library's
//! public API, wgpu and egui, no window system (the window loop, its keys and the
//! command line stay with the application). The viewer's parameter model is
//! [`crate::app::Effect::set`].
//!
//! - [`present`]: the image pass ([`present::Presenter`]): a texture drawn into
//!   a window's surface, fitted, with exposure, a split view, false colours for
//!   one-channel and vector images (`shaders/view/present.wgsl`).
//! - [`inspect`]: the pass list of a prepared effect ([`inspect::pass_rows`]) and
//!   what is inspected (a pass, the output, the input, an AUX image), with the
//!   value ranges that shade it.
//! - [`panel`]: the egui control panel ([`panel::show`]): the parameters of the
//!   effect and of every pass, the pass list to inspect, the view; changes come
//!   back as [`panel::UiEvent`]s. [`ui_state::UiState`] is what it edits (fit,
//!   zoom, split, exposure, what is inspected), [`command::Command`] what its
//!   buttons ask for; [`model::Model`] what it shows.
//! - [`fx`]: the effect shown and its parameters ([`fx::Fx`], over
//!   [`crate::app::Effect::set`]).
//! - [`content`]: what is shown ([`content::Content`]): still images
//!   ([`stills`]), a sequence played through a stream ([`playback`]), or a scene
//!   ([`scene_view`], rendered through [`crate::app::scene_frames`]).
//! - [`camera_control`]: orbit, pan, dolly and fly of a scene camera
//!   ([`camera_control::CameraControl`]).
//! - [`panel_cache`]: an egui panel drawn into a texture once and reused while
//!   nothing changes ([`panel_cache::PanelCache`]).
//! - [`frame_paint`]: the steps of painting a frame that need no window (the
//!   image area, egui's textures, the image and the cached panel).
//! - [`fps`]: the frames-per-second readout ([`fps::FpsCounter`]).

pub mod camera_control;
pub mod command;
pub mod content;
pub mod fps;
pub mod frame_paint;
pub mod fx;
pub mod inspect;
pub mod model;
pub mod panel;
pub mod panel_cache;
pub mod playback;
pub mod present;
pub mod scene_view;
pub mod stills;
pub mod ui_state;
