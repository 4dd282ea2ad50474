//! What travels between the pipeline's stages ([`super::run_frames`]): decoded
//! frames to the GPU stage, read-backs to the encoder.

use super::frames::Picture;
use crate::gpu::context::PendingReadback;
use crate::gpu::yuv::PendingPlanes;
use crate::io::{Image, IoError};
use crate::script::types::Format;
use std::time::Duration;

/// A decoded frame on its way to the GPU: position, number, name, frame, decode time.
pub(super) type Decoded = (
    usize,
    u64,
    String,
    Result<(Picture, Vec<(String, Image)>), IoError>,
    Duration,
);

/// An output being read back: a texture's texels, or the Y'CbCr planes the GPU made
/// of it (with the frame's width and height).
pub(super) enum Readback {
    Texture(PendingReadback),
    Planes(PendingPlanes, u32, u32),
}

impl Readback {
    pub(super) fn size(&self) -> (u32, u32) {
        match self {
            Readback::Texture(p) => (p.width(), p.height()),
            Readback::Planes(_, w, h) => (*w, *h),
        }
    }
}

/// A read-back on its way to the encoder.
pub(super) struct Encoded {
    pub(super) index: usize,
    pub(super) number: u64,
    pub(super) name: String,
    pub(super) pending: Readback,
    pub(super) format: Format,
    pub(super) gpu: Option<Duration>,
    pub(super) decode: Option<Duration>,
}
