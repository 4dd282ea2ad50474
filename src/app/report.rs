//! What a job did and where its time went: one type for every job (an image, a batch
//! of images, a sequence or y4m stream, a rendered scene), so that `fxrun` has one
//! printer and `--timings-json` one schema.

use super::error::RunError;
use crate::gpu::executor::PassTiming;
use std::time::Duration;

/// The kind of job a [`RunReport`] describes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum JobKind {
    /// One image file to one output file.
    #[default]
    Image,
    /// Independent stills (a folder, a glob, several files): sizes may differ.
    Batch,
    /// Frames of one size in order (numbered files, y4m): temporal effects.
    Sequence,
    /// A scene rendered by the deferred renderer, then the effect chain.
    Scene,
}

/// A frame (an image of a batch, a frame of a sequence) that was written.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameDone {
    /// Position of its input in the job (0-based).
    pub index: usize,
    /// Its input (a file name, `stdin frame N`, the scene) and where it went.
    pub input: String,
    pub output: String,
    /// Size of the output.
    pub width: u32,
    pub height: u32,
    /// Reading and decoding its input (None where frames and outputs do not pair up
    /// one to one: temporal effects with latency or rate 2 report per-stage totals).
    pub decode_ms: Option<f64>,
    /// The GPU thread's time for it (planning when the size changed, upload, passes).
    pub gpu_ms: Option<f64>,
    /// Waiting for the read-back, converting and writing it.
    pub encode_ms: f64,
}

impl FrameDone {
    /// The frame's own processing time: decode + GPU + encode (queues not counted).
    pub fn total_ms(&self) -> f64 {
        self.decode_ms.unwrap_or(0.0) + self.gpu_ms.unwrap_or(0.0) + self.encode_ms
    }
}

/// A frame that failed.
#[derive(Debug, serde::Serialize)]
pub struct FrameFailure {
    /// Position of its input in the job.
    pub index: usize,
    pub input: String,
    /// The error, rendered (it names the file).
    pub message: String,
    #[serde(skip)]
    pub error: RunError,
}

impl FrameFailure {
    pub fn new(index: usize, input: impl Into<String>, error: RunError) -> Self {
        FrameFailure {
            index,
            input: input.into(),
            message: error.to_string(),
            error,
        }
    }
}

/// Busy time of each stage of the pipeline (the rest of the wall time it waited on a
/// queue).
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct StageTimes {
    pub decode_busy_ms: f64,
    pub gpu_busy_ms: f64,
    pub encode_busy_ms: f64,
    /// Time the encode thread waited for the GPU to finish frames (not busy).
    pub readback_wait_ms: f64,
}

/// The steps of one frame on the GPU thread (an image job's only frame).
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct FrameSteps {
    /// Planning and building the pipelines.
    pub pipeline_ms: f64,
    pub upload_ms: f64,
    pub passes_ms: f64,
    pub readback_ms: f64,
}

/// Transient texture memory of the last plan.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct MemoryReport {
    pub peak_bytes: u64,
    pub lower_bound_bytes: u64,
    pub naive_bytes: u64,
}

impl MemoryReport {
    /// The memory figures of a plan.
    pub fn of(plan: &crate::graph::plan::Plan) -> Self {
        MemoryReport {
            peak_bytes: plan.peak_bytes,
            lower_bound_bytes: plan.lower_bound_bytes,
            naive_bytes: plan.naive_bytes,
        }
    }
}

/// What the deferred renderer did (scene jobs).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SceneStats {
    pub scene: String,
    pub technique: String,
    pub light_culling: String,
    pub shadows: String,
    /// How deferred shading filled the G-buffer: `fat` or `visibility`
    /// (`--gbuffer-layout`; `fat` where the adapter cannot have a visibility
    /// buffer).
    pub gbuffer_layout: String,
    pub load_ms: f64,
    /// The renderer's CPU time of every frame's own steps, summed over the
    /// frames (without `render_pipelines_ms`).
    pub render_cpu_ms: f64,
    /// Where the render CPU time went (summed over the frames): pose, lights,
    /// upload, record (`RenderStats::cpu_split`).
    pub render_cpu_split: Vec<(String, f64)>,
    /// CPU time creating the render pipelines, on their first use (once per
    /// run for a sequence: `RenderStats::pipeline_ms`).
    pub render_pipelines_ms: f64,
    pub render_gpu_ms: Option<f64>,
    pub render_passes: Vec<(String, f64)>,
    pub triangles: usize,
    pub lights_visible: usize,
    /// Light × cluster entries the GPU listed (timed frames) and the bytes
    /// reserved for the lists (clustered culling).
    pub cluster_entries: usize,
    pub cluster_bytes: u64,
    /// Shadow-map layers a frame uses and the bytes of the shadow-map texture.
    pub shadow_layers: usize,
    /// Layers rendered, over all frames (the shadow cache keeps a layer while
    /// nothing in its light's view changes).
    pub shadow_layers_rendered: usize,
    pub shadow_map_bytes: u64,
    /// One line per material (with `describe_materials`).
    pub materials: Vec<String>,
    pub pipelines: usize,
    pub shader_modules: usize,
}

impl SceneStats {
    /// The counts of one rendered frame (each render pass's time, triangles,
    /// lights, clusters, shadow maps, pipelines): a still's, or the last frame's
    /// of a sequence.
    pub(crate) fn take_frame_counts(&mut self, rs: &crate::render::renderer::RenderStats) {
        self.render_passes = rs.pass_ms.clone();
        self.triangles = rs.triangles;
        self.lights_visible = rs.lights_visible;
        self.cluster_entries = rs.cluster_entries;
        self.cluster_bytes = rs.cluster_bytes;
        self.shadow_layers = rs.shadow_layers;
        self.shadow_map_bytes = rs.shadow_map_bytes;
        self.pipelines = rs.pipelines;
        self.shader_modules = rs.shader_modules;
    }
}

/// What a job did and where its time went.
#[derive(Debug, Default, serde::Serialize)]
pub struct RunReport {
    pub job: JobKind,
    pub adapter: String,
    pub backend: String,
    /// Sequences of y4m or video frames: whether the GPU converted the input's
    /// Y'CbCr planes and made the output's (else the CPU did).
    pub ycbcr_on_gpu: [bool; 2],
    /// Frames in the job when known before it starts (an image: 1, a batch: its
    /// images, numbered files: their count; a pipe: unknown).
    pub frames_total: Option<u64>,
    /// Frames read from the source.
    pub frames_in: u64,
    /// Outputs written, in order.
    pub done: Vec<FrameDone>,
    /// Frames that failed, in order.
    pub failed: Vec<FrameFailure>,
    /// Times the effect was planned and its textures allocated (once per run of
    /// frames of the same size and formats).
    pub plans: usize,
    /// Stopped early (Ctrl-C).
    pub interrupted: bool,
    pub wall_ms: f64,
    pub compile_ms: f64,
    /// Waiting for the device after the first decode (it is created meanwhile), and
    /// creating it (on a thread); 0 with a caller's engine.
    pub device_wait_ms: f64,
    pub device_created_ms: f64,
    pub stages: StageTimes,
    /// The GPU steps of the last frame planned (an image job: its only frame).
    pub steps: FrameSteps,
    /// Per-pass timings of the last frame (with timings on).
    pub passes: Vec<PassTiming>,
    pub memory: MemoryReport,
    /// The bound on frames held in memory at once (queues + input ring).
    pub frames_held_max: usize,
    pub scene: Option<SceneStats>,
    /// Compiler warnings and notes (informational: an automatic conversion), rendered.
    #[serde(skip)]
    pub warnings: String,
    #[serde(skip)]
    pub notes: String,
}

impl RunReport {
    /// Frames neither written nor failed: those after the failure that stopped the
    /// job, or after an interruption (0 when the total is unknown).
    pub fn not_run(&self) -> u64 {
        self.frames_total
            .unwrap_or(0)
            .saturating_sub(self.done.len() as u64 + self.failed.len() as u64)
    }

    /// Median of the written frames' processing times ([`FrameDone::total_ms`]), 0
    /// when none was written.
    pub fn median_ms(&self) -> f64 {
        let mut t: Vec<f64> = self.done.iter().map(FrameDone::total_ms).collect();
        if t.is_empty() {
            return 0.0;
        }
        t.sort_by(f64::total_cmp);
        let n = t.len();
        if n % 2 == 1 {
            t[n / 2]
        } else {
            (t[n / 2 - 1] + t[n / 2]) / 2.0
        }
    }

    /// Outputs per second of wall time.
    pub fn fps(&self) -> f64 {
        self.done.len() as f64 / (self.wall_ms / 1e3).max(1e-9)
    }

    /// Busy fraction of each stage over the wall time: (decode, gpu, encode).
    pub fn utilisation(&self) -> (f64, f64, f64) {
        let w = self.wall_ms.max(1e-9);
        (
            self.stages.decode_busy_ms / w,
            self.stages.gpu_busy_ms / w,
            self.stages.encode_busy_ms / w,
        )
    }
}

/// Milliseconds of a duration.
pub(crate) fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Progress of a run, for a progress bar.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    pub done: u64,
    pub total: Option<u64>,
    pub elapsed: Duration,
}
