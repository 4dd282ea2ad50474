//! What travels between the pipeline's stages ([`super::run_frames`]): decoded
//! frames to the GPU stage, read-backs to the encoder.

use crate::gpu::context::PendingReadback;
use crate::io::{Image, IoError};
use crate::script::types::Format;
use std::time::Duration;

/// A decoded frame on its way to the GPU: position, number, name, frame, decode time.
pub(super) type Decoded = (
    usize,
    u64,
    String,
    Result<(Image, Vec<(String, Image)>), IoError>,
    Duration,
);

/// A read-back on its way to the encoder.
pub(super) struct Encoded {
    pub(super) index: usize,
    pub(super) number: u64,
    pub(super) name: String,
    pub(super) pending: PendingReadback,
    pub(super) format: Format,
    pub(super) gpu: Option<Duration>,
    pub(super) decode: Option<Duration>,
}
