//! One image file through an effect chain to one output file: `fxrun EFFECT -i IN -o
//! OUT`. A one-frame run of [`super::pipeline`] (`Mode::Stills`), whose device is
//! created on a thread while the image is read and decoded.

use super::effect::Effect;
use super::error::RunError;
use super::pipeline::{
    run_frames, Device, FrameSource, Mode, PipelineOptions, SideLimit, SourceFrame,
};
use super::report::{ms, JobKind, RunReport};
use super::sources::{load_checked, FilesSink, OutputNames};
use crate::gpu::context::AdapterChoice;
use crate::gpu::executor::Engine;
use crate::io::{self, FileFormat, IoError, LoadOptions, SaveOptions};
use crate::script::types::Format;
use crate::script::Diagnostics;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// The output texture format for a file: 8-bit files get rgba8-srgb (rgba8 with
/// `assume_linear`), 16-bit and half EXR rgba16f, 32-bit EXR rgba32f.
pub fn output_format_for(
    path: &Path,
    bit_depth: Option<u8>,
    assume_linear: bool,
) -> Result<Format, IoError> {
    let ff = FileFormat::from_path(path).ok_or_else(|| IoError::Unsupported {
        path: path.to_path_buf(),
        message: "unknown output file type (use .png, .jpg, .exr, .tif, ...)".into(),
    })?;
    let bits = bit_depth.unwrap_or(ff.default_bit_depth());
    if !ff.supports_bit_depth(bits) {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            message: format!(
                "{} files cannot have {bits}-bit channels (supported: {:?})",
                ff.name(),
                ff.bit_depths()
            ),
        });
    }
    Ok(match (ff, bits) {
        (FileFormat::Exr, 32) => Format::Rgba32f,
        (_, 8) if assume_linear => Format::Rgba8,
        (_, 8) => Format::Rgba8Srgb,
        (_, 32) => Format::Rgba32f,
        _ => Format::Rgba16f,
    })
}

/// Options of [`apply_to_image`].
#[derive(Debug, Clone, Default)]
pub struct ImageJob {
    pub effects: Vec<String>,
    pub overrides: Vec<crate::graph::Override>,
    pub input: PathBuf,
    pub output: PathBuf,
    pub bit_depth: Option<u8>,
    pub assume_linear: bool,
    /// `--aux NAME=FILE` images.
    pub aux: Vec<(String, PathBuf)>,
    pub timings: bool,
    /// The viewport: the output size passes scale from as `VIEWPORT` (`None`:
    /// each input's size; `fxrun --size`).
    pub viewport: Option<(u32, u32)>,
}

/// The image and its auxiliary images.
struct StillSource {
    input: PathBuf,
    aux: Vec<(String, PathBuf)>,
    load: LoadOptions,
    limit: SideLimit,
    done: bool,
}

impl StillSource {
    fn load(&self) -> Result<(crate::io::Image, Vec<(String, crate::io::Image)>), IoError> {
        let img = load_checked(&self.input, &self.limit, &self.load)?;
        let mut aux = Vec::new();
        for (name, path) in &self.aux {
            aux.push((name.clone(), load_checked(path, &self.limit, &self.load)?));
        }
        Ok((img, aux))
    }
}

impl FrameSource for StillSource {
    fn frame_count(&self) -> Option<u64> {
        Some(1)
    }
    fn next_frame(&mut self) -> Option<SourceFrame> {
        if std::mem::replace(&mut self.done, true) {
            return None;
        }
        let (image, aux) = match self.load() {
            Ok((img, aux)) => (Ok(img.into()), aux),
            Err(e) => (Err(e), Vec::new()),
        };
        Some(SourceFrame {
            number: 0,
            name: self.input.display().to_string(),
            image,
            aux,
        })
    }
    fn set_limit(&mut self, limit: SideLimit) {
        self.limit = limit;
    }
}

/// Apply an effect chain to an image file and write the result atomically. With no
/// `engine`, the device is created on a thread while the image is read and decoded.
/// A failure of the image is returned as the error (nothing is written).
pub fn apply_to_image(
    job: &ImageJob,
    engine: Option<&mut Engine>,
    adapter: &AdapterChoice,
) -> Result<RunReport, RunError> {
    let device = match engine {
        Some(e) => Device::Engine(e),
        None => Device::Create(adapter),
    };
    apply(job, device)
}

/// [`apply_to_image`] on the engine `kept` holds; when it holds none, on one created
/// while the image decodes and left in `kept` (also when the run fails), so that the
/// caller decides when the device is destroyed (`fxrun` exits without destroying
/// it: [`Device::CreateInto`]).
pub fn apply_to_image_kept(
    job: &ImageJob,
    kept: &mut Option<Engine>,
    adapter: &AdapterChoice,
) -> Result<RunReport, RunError> {
    apply(job, Device::kept(kept, adapter))
}

/// [`apply_to_image`] on `device`.
fn apply(job: &ImageJob, device: Device) -> Result<RunReport, RunError> {
    let t = Instant::now();
    let mut effect = Effect::compile_overrides(&job.effects, job.overrides.clone())?;
    let compile_ms = ms(t.elapsed());
    // Fail on the output path before doing the work.
    let out_format = output_format_for(&job.output, job.bit_depth, job.assume_linear)?;
    let load = LoadOptions {
        assume_linear: job.assume_linear,
    };
    let source = StillSource {
        input: job.input.clone(),
        aux: job.aux.clone(),
        load,
        limit: SideLimit::known(io::MAX_SIDE),
        done: false,
    };
    let sink = FilesSink {
        names: OutputNames::Named([(0, job.output.clone())].into()),
        save: SaveOptions {
            bit_depth: job.bit_depth,
            assume_linear: job.assume_linear,
        },
    };
    let opts = PipelineOptions {
        mode: Mode::Stills,
        job: JobKind::Image,
        output_format: out_format,
        assume_linear: job.assume_linear,
        queue: 1,
        timings: job.timings,
        viewport: job.viewport,
        ..Default::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let mut report = run_frames(
        device,
        &mut effect,
        Box::new(source),
        Box::new(sink),
        &opts,
        stop,
        |_| {},
    )?;
    if let Some(f) = report.failed.drain(..).next() {
        return Err(f.error);
    }
    report.compile_ms = compile_ms;
    report.wall_ms += compile_ms;
    let (warnings, notes) = effect.warnings.clone().split_notes();
    let render = |d: Diagnostics| {
        if d.is_empty() {
            String::new()
        } else {
            d.render(&effect.sources)
        }
    };
    report.warnings = render(warnings);
    report.notes = render(notes);
    Ok(report)
}
