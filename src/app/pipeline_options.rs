//! The options of a run of the pipeline ([`super::run_frames`]): how frames relate
//! ([`Mode`]) and [`PipelineOptions`]. Their own home, so the pipeline's stages
//! read them without importing the pipeline.

use super::planes::PlaneConversion;
use super::report::JobKind;
use crate::gpu::executor::CameraStd;
use crate::script::types::Format;

/// How frames relate (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Stills,
    Sequence,
}

/// Options of [`run_frames`].
#[derive(Debug, Clone)]
pub struct PipelineOptions {
    pub mode: Mode,
    /// The kind of job, for the report.
    pub job: JobKind,
    /// Texture format of the outputs (rgba8-srgb for 8-bit files, rgba16f/32f for EXR).
    pub output_format: Format,
    /// Per frame number, when outputs differ in file type (a batch to several
    /// formats); frames past its end use `output_format`.
    pub output_formats: Vec<Format>,
    pub assume_linear: bool,
    /// Outputs per input frame (2: field-rate deinterlacing). Sequences only.
    pub rate: u32,
    pub fps: f64,
    /// Input frame numbers whose outputs are written (a shard); frames outside it are
    /// read only as context. `None`: all. Sequences only.
    pub emit: Option<(u64, u64)>,
    /// Standard camera values for the effect (a rendered input).
    pub camera: Option<CameraStd>,
    /// Stills: go on after a failed frame (the default is to stop at the first one).
    pub keep_going: bool,
    /// Depth of each queue between stages.
    pub queue: usize,
    pub timings: bool,
    /// Where the Y'CbCr frames of y4m and video streams are converted (sequences).
    pub ycbcr: PlaneConversion,
    /// The viewport: the output size passes scale from as `VIEWPORT` (`None`:
    /// each input's size; `fxrun --size`).
    pub viewport: Option<(u32, u32)>,
}

impl Default for PipelineOptions {
    fn default() -> Self {
        PipelineOptions {
            mode: Mode::Sequence,
            job: JobKind::Sequence,
            output_format: Format::Rgba8Srgb,
            output_formats: Vec::new(),
            assume_linear: false,
            rate: 1,
            fps: 25.0,
            emit: None,
            camera: None,
            keep_going: false,
            queue: 3,
            timings: false,
            ycbcr: PlaneConversion::Auto,
            viewport: None,
        }
    }
}

impl PipelineOptions {
    pub(super) fn format_for(&self, number: u64) -> Format {
        usize::try_from(number)
            .ok()
            .and_then(|i| self.output_formats.get(i).copied())
            .unwrap_or(self.output_format)
    }
}
