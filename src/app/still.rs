//! One image file through an effect chain to one output file: `fxrun EFFECT -i IN -o OUT`.

use super::effect::{run_on_image, Effect};
use super::error::RunError;
use super::report::{ms, FrameDone, JobKind, RunReport};
use crate::gpu::context::{AdapterChoice, GpuContext};
use crate::gpu::executor::Engine;
use crate::io::{self, FileFormat, Image, IoError, LoadOptions, SaveOptions};
use crate::script::types::Format;
use crate::script::Diagnostics;
use std::path::{Path, PathBuf};
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
    pub overrides: Vec<String>,
    pub input: PathBuf,
    pub output: PathBuf,
    pub bit_depth: Option<u8>,
    pub assume_linear: bool,
    /// `--aux NAME=FILE` images.
    pub aux: Vec<(String, PathBuf)>,
    pub timings: bool,
}

/// Apply an effect chain to an image file and write the result atomically.
pub fn apply_to_image(
    job: &ImageJob,
    engine: Option<&mut Engine>,
    adapter: &AdapterChoice,
) -> Result<RunReport, RunError> {
    let t_all = Instant::now();
    let mut report = RunReport {
        job: JobKind::Image,
        frames_total: Some(1),
        ..Default::default()
    };
    let t = Instant::now();
    let mut effect = Effect::compile(&job.effects, &job.overrides)?;
    report.compile_ms = ms(t.elapsed());
    // Fail on the output path before doing the work.
    let out_format = output_format_for(&job.output, job.bit_depth, job.assume_linear)?;
    let t = Instant::now();
    let load = LoadOptions {
        assume_linear: job.assume_linear,
    };
    // Without an engine, the device is created on a thread while the files are read
    // and decoded (on lavapipe each takes tens of milliseconds). An image larger than
    // the device takes is still refused before its decode: the header check below
    // waits for the device only then.
    std::thread::scope(|scope| -> Result<RunReport, RunError> {
        let mut device_thread = engine.is_none().then(|| {
            scope.spawn(|| {
                let t = Instant::now();
                GpuContext::new(adapter).map(|ctx| (Engine::new(ctx), ms(t.elapsed())))
            })
        });
        let mut own_engine: Option<(Engine, f64)> = None;
        let mut engine = engine;
        let mut wait_device = |own: &mut Option<(Engine, f64)>| -> Result<(), RunError> {
            if let Some(h) = device_thread.take() {
                let r = h.join().expect("the device thread panicked")?;
                *own = Some(r);
            }
            Ok(())
        };
        // Headers first: a size the device cannot take is refused before the decode.
        let mut files = Vec::new();
        for path in std::iter::once(&job.input).chain(job.aux.iter().map(|(_, p)| p)) {
            let bytes = io::read_image_file(path)?;
            let size = io::image_dimensions(&bytes, path)?;
            files.push((path, bytes, size));
        }
        let largest = files.iter().map(|f| f.2 .0.max(f.2 .1)).max().unwrap_or(0);
        if largest > wgpu::Limits::default().max_texture_dimension_2d {
            // Larger than every device takes: ask this one before decoding.
            wait_device(&mut own_engine)?;
            let max = match (&engine, &own_engine) {
                (Some(e), _) => e.ctx.device.limits().max_texture_dimension_2d,
                (None, Some((e, _))) => e.ctx.device.limits().max_texture_dimension_2d,
                (None, None) => unreachable!("an engine or a device thread"),
            };
            let name = match (&engine, &own_engine) {
                (Some(e), _) => e.ctx.info.name.clone(),
                (_, Some((e, _))) => e.ctx.info.name.clone(),
                _ => String::new(),
            };
            for (path, _, (w, h)) in &files {
                if (*w).max(*h) > max {
                    return Err(RunError::BadInput(IoError::Decode {
                        path: (*path).clone(),
                        message: format!(
                            "the image is {w}x{h}, larger than the GPU's limit of {max} pixels per side ({name})"
                        ),
                    }));
                }
            }
        }
        let img = io::decode_image(&files[0].1, &job.input, &load)?;
        let mut aux_imgs = Vec::new();
        for ((name, path), (_, bytes, _)) in job.aux.iter().zip(&files[1..]) {
            let a = io::decode_image(bytes, path, &load)?;
            if (a.width, a.height) != (img.width, img.height) {
                return Err(RunError::BadInput(IoError::Unsupported {
                    path: path.clone(),
                    message: format!(
                        "auxiliary image is {}x{}, the input is {}x{}",
                        a.width, a.height, img.width, img.height
                    ),
                }));
            }
            aux_imgs.push((name.clone(), a));
        }
        report.stages.decode_busy_ms = ms(t.elapsed());
        report.frames_in = 1;
        let t = Instant::now();
        drop(files);
        wait_device(&mut own_engine)?;
        // The time spent waiting for the device after the decode (its creation on
        // the thread is `device_created_ms`).
        report.device_wait_ms = ms(t.elapsed());
        let engine: &mut Engine = match (engine.take(), own_engine.as_mut()) {
            (Some(e), _) => e,
            (None, Some((e, created))) => {
                report.device_created_ms = *created;
                e
            }
            (None, None) => unreachable!("an engine or a device thread"),
        };
        finish_job(
            job,
            engine,
            &mut effect,
            &img,
            &aux_imgs,
            out_format,
            report,
            t_all,
        )
    })
}

/// The rest of [`apply_to_image`] once the image is decoded and the device exists:
/// run, then encode and write the output.
#[allow(clippy::too_many_arguments)]
fn finish_job(
    job: &ImageJob,
    engine: &mut Engine,
    effect: &mut Effect,
    img: &Image,
    aux_imgs: &[(String, Image)],
    out_format: Format,
    mut report: RunReport,
    t_all: Instant,
) -> Result<RunReport, RunError> {
    report.adapter = engine.ctx.info.name.clone();
    report.backend = format!("{:?}", engine.ctx.info.backend);
    let aux: Vec<(String, &Image)> = aux_imgs.iter().map(|(n, a)| (n.clone(), a)).collect();
    let t = Instant::now();
    let (width, height, pixels) = run_on_image(
        engine,
        effect,
        img,
        &aux,
        out_format,
        job.assume_linear,
        job.timings,
        &mut report,
    )?;
    let gpu_ms = ms(t.elapsed());
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
    let t = Instant::now();
    io::save_image(
        &job.output,
        width,
        height,
        &pixels,
        &SaveOptions {
            bit_depth: job.bit_depth,
            assume_linear: job.assume_linear,
        },
    )?;
    let encode_ms = ms(t.elapsed());
    report.stages.encode_busy_ms = encode_ms;
    report.stages.gpu_busy_ms = gpu_ms;
    report.done.push(FrameDone {
        index: 0,
        input: job.input.display().to_string(),
        output: job.output.display().to_string(),
        width,
        height,
        decode_ms: Some(report.stages.decode_busy_ms),
        gpu_ms: Some(gpu_ms),
        encode_ms,
    });
    report.wall_ms = ms(t_all.elapsed());
    Ok(report)
}
