//! The application layer: jobs that join sources (image files, folders of stills,
//! numbered frames, y4m files and pipes, the scene renderer, a caller's memory), a
//! compiled effect on the GPU, and sinks (files, folders, patterns, y4m, memory),
//! with one report type ([`RunReport`]) for all of them. `fxrun` is a thin command
//! line over this module; Rust programs may use it or go one layer down to
//! [`crate::gpu`] (device, transfers, executor) and record frames themselves.
//!
//! - [`effect`]: [`Effect`] (compile, prepare); [`effect_params`]: [`Effect::set`]
//!   and [`Change`]; [`in_memory`]: [`apply_in_memory`].
//! - [`still`]: one image file to one output file ([`apply_to_image`]).
//! - [`batch`]: independent stills of any size through one process ([`run_batch`]).
//! - [`sequence`]: frames of one size in order, temporal effects ([`run_sequence`]).
//! - [`pipeline`]: the one pipeline under all three ([`run_frames`]): a
//!   [`FrameSource`] (decode thread) → the effect on the GPU → a [`FrameSink`] (encode
//!   thread) ([`frames`]: the traits; [`pipeline_options`]: [`Mode`],
//!   [`PipelineOptions`]; `gpu_stage.rs`: the GPU stage; `stage_messages.rs`: what
//!   travels between the stages); [`sources`]:
//!   files, y4m, memory; [`streams`]: y4m on stdin/stdout, y4m files and video files
//!   (through ffmpeg) opened for a run.
//! - [`scene`]: render a scene, then the effects ([`run_scene_job`]); [`gbuffer`]:
//!   its G-buffer as files ([`write_gbuffer`]); [`scene_frames`]: a scene
//!   rendered live, frame by frame, through an effect ([`SceneFrames`]: what
//!   `fxrun --view` shows a scene with).
//! - [`report`]: [`RunReport`]; [`error`]: [`RunError`].

pub mod batch;
pub mod effect;
pub mod effect_params;
mod effect_settings;
pub mod error;
pub mod frames;
pub mod gbuffer;
mod gpu_planes;
mod gpu_stage;
pub mod in_memory;
pub mod pipeline;
pub mod pipeline_cache;
pub mod pipeline_options;
pub mod planes;
pub mod report;
pub mod scene;
mod scene_errors;
pub mod scene_frames;
pub mod scene_sequence;
pub mod sequence;
pub mod sources;
mod stage_messages;
pub mod still;
pub mod streams;

pub use batch::{run_batch, BatchItem, BatchOptions};
pub use effect::Effect;
pub use effect_params::Change;
pub use error::RunError;
pub use gbuffer::write_gbuffer;
pub use in_memory::apply_in_memory;
pub use pipeline::{
    run_frames, Device, FrameSink, FrameSource, Mode, OutputFrame, PipelineOptions, SourceFrame,
};
pub use report::{FrameDone, FrameFailure, JobKind, Progress, RunReport};
pub use scene::{run_scene_job, SceneJob};
pub use scene_frames::{SceneFrame, SceneFrames};
pub use scene_sequence::{run_scene_sequence, SceneTimes};
pub use sequence::{run_sequence, SequenceOptions};
pub use sources::{
    DiscardSink, FilesSink, FilesSource, MemorySink, MemorySource, OutputNames, Y4mSink, Y4mSource,
};
pub use still::{apply_to_image, apply_to_image_kept, output_format_for, ImageJob};
pub use streams::{
    open_output, texture_format_for_depth, OpenedInput, OpenedOutput, OutputSettings, StreamInput,
    StreamOutput,
};
