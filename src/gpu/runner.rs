//! Running effects on images: the library API behind `fxrun` and for Rust programs.
//!
//! - [`Effect`]: a compiled effect chain (no device needed).
//! - [`Effect::prepare`]: plan it for an input size/format and build its pipelines on
//!   an [`Engine`] (which may wrap the caller's own device: [`GpuContext::from_existing`]).
//! - [`apply_to_image`]: the whole file-to-file job of `fxrun -i -o`.

use super::context::{GpuContext, GpuError};
use super::executor::{wgpu_format, Engine, ExecError, FrameInputs, PassTiming, Prepared};
use crate::graph::plan::{plan, InputDesc, PlanOptions};
use crate::graph::Graph;
use crate::io::{self, FileFormat, Image, IoError, LoadOptions, Pixels, SaveOptions};
use crate::script::types::{ColorSpace, Format};
use crate::script::{Diagnostics, SourceMap};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Errors of a run. [`RunError::is_input_error`] tells the caller's input (the
/// effect, a file, an argument) from a fault of the system (I/O, GPU, internal);
/// what that means for an exit status is the application's business.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The effect, its shaders or a `--set` were rejected (diagnostics rendered).
    #[error("{rendered}")]
    Rejected { rendered: String },
    /// An input file was rejected (corrupt, unsupported).
    #[error(transparent)]
    BadInput(IoError),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(IoError),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("{0}")]
    Other(String),
}

impl RunError {
    /// True when the input was rejected (the effect, its shaders, a `--set`, an
    /// image file); false for I/O, GPU and internal faults.
    pub fn is_input_error(&self) -> bool {
        match self {
            RunError::Rejected { .. } | RunError::BadInput(_) => true,
            RunError::Io(_) | RunError::Gpu(_) | RunError::Other(_) => false,
        }
    }
}

/// Errors of running a prepared effect (its diagnostics were reported when it
/// was prepared, so a rejection here is internal).
impl From<ExecError> for RunError {
    fn from(e: ExecError) -> Self {
        match e {
            ExecError::Gpu(g) => RunError::Gpu(g),
            ExecError::Rejected(d) => RunError::Other(format!(
                "{} error(s) in the effect or its shaders",
                d.error_count()
            )),
            ExecError::Input(s) => RunError::Other(s),
        }
    }
}

impl From<IoError> for RunError {
    fn from(e: IoError) -> Self {
        if e.is_input_error() {
            RunError::BadInput(e)
        } else {
            RunError::Io(e)
        }
    }
}

/// A compiled effect chain.
pub struct Effect {
    pub graph: Graph,
    pub sources: SourceMap,
    /// Warnings and notes from compiling.
    pub warnings: Diagnostics,
}

impl Effect {
    /// Compile a chain of effects (paths or built-in names) with `NAME=VALUE` overrides.
    pub fn compile(effects: &[String], overrides: &[String]) -> Result<Effect, RunError> {
        let req = crate::lookup::DiskEffects::request(effects, overrides);
        let (graph, diags, sources) = crate::shader::compile_all(&req);
        match graph {
            Some(graph) if !diags.has_errors() => Ok(Effect {
                graph,
                sources,
                warnings: diags,
            }),
            _ => Err(RunError::Rejected {
                rendered: diags.render(&sources),
            }),
        }
    }

    /// Plan for `input` and prepare on `engine`; the output is rendered in
    /// `output_format` (None: the output pass's own format).
    pub fn prepare(
        &mut self,
        engine: &mut Engine,
        input: &InputDesc,
        output_format: Option<Format>,
    ) -> Result<Prepared, RunError> {
        let opts = PlanOptions {
            output_format,
            ..Default::default()
        };
        self.prepare_with(engine, input, &opts)
    }

    /// [`Effect::prepare`] with explicit plan options (e.g. `ReusePolicy::Pool` for
    /// streams, which keep their textures across frames).
    pub fn prepare_with(
        &mut self,
        engine: &mut Engine,
        input: &InputDesc,
        opts: &PlanOptions,
    ) -> Result<Prepared, RunError> {
        let (p, notes) = plan(&self.graph, input, opts).map_err(|d| RunError::Rejected {
            rendered: d.render(&self.sources),
        })?;
        self.warnings.extend(notes);
        engine
            .prepare(&self.graph, p, &mut self.sources)
            .map_err(|e| match e {
                ExecError::Rejected(d) => RunError::Rejected {
                    rendered: d.render(&self.sources),
                },
                ExecError::Gpu(g) => RunError::Gpu(g),
                ExecError::Input(s) => RunError::Other(s),
            })
    }
}

/// The texture format an image is uploaded as, and what its samples mean.
pub fn input_format(img: &Image, assume_linear: bool) -> (Format, ColorSpace) {
    match img.pixels {
        Pixels::U8(_) if assume_linear => (Format::Rgba8, ColorSpace::Linear),
        Pixels::U8(_) => (Format::Rgba8Srgb, ColorSpace::Linear),
        Pixels::F32(_) => (Format::Rgba16f, ColorSpace::Linear),
    }
}

/// Upload an image as a texture of `format` (from [`input_format`]).
pub fn upload_image(
    ctx: &GpuContext,
    label: &str,
    img: &Image,
    format: Format,
) -> Result<wgpu::Texture, GpuError> {
    let bytes = image_bytes(img, format);
    ctx.upload_texture(
        label,
        img.width,
        img.height,
        wgpu_format(format),
        &bytes,
        wgpu::TextureUsages::empty(),
    )
}

/// An image's pixels as the tightly packed texel bytes of `format` (from [`input_format`]).
pub fn image_bytes(img: &Image, format: Format) -> Vec<u8> {
    match (&img.pixels, format) {
        (Pixels::U8(v), Format::Rgba8 | Format::Rgba8Srgb) => v.clone(),
        (Pixels::F32(v), Format::Rgba16f) => v
            .iter()
            .flat_map(|&x| half::f16::from_f32(x).to_le_bytes())
            .collect(),
        (Pixels::F32(v), Format::Rgba32f) => v.iter().flat_map(|&x| x.to_le_bytes()).collect(),
        (p, f) => {
            let lin = p.to_f32_linear(false);
            match f {
                Format::Rgba16f => lin
                    .iter()
                    .flat_map(|&x| half::f16::from_f32(x).to_le_bytes())
                    .collect(),
                _ => lin.iter().flat_map(|&x| x.to_le_bytes()).collect(),
            }
        }
    }
}

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

/// Read a texture back as pixels (U8 for 8-bit formats, linear F32 otherwise).
pub fn read_pixels(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    format: Format,
) -> Result<Pixels, GpuError> {
    pixels_from_bytes(ctx.read_texture(texture)?, format)
}

/// Tightly packed texel bytes of `format` as pixels.
pub fn pixels_from_bytes(raw: Vec<u8>, format: Format) -> Result<Pixels, GpuError> {
    Ok(match format {
        Format::Rgba8 | Format::Rgba8Srgb => Pixels::U8(raw),
        Format::Rgba16f => Pixels::F32(
            raw.chunks_exact(2)
                .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
                .collect(),
        ),
        Format::Rgba32f => Pixels::F32(
            raw.chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        other => {
            return Err(GpuError::Map(format!(
                "cannot read back {other} as an image"
            )))
        }
    })
}

/// Create an output texture for a plan.
pub fn create_output(ctx: &GpuContext, width: u32, height: u32, format: Format) -> wgpu::Texture {
    ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("fxgraph output"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu_format(format),
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING,
        // An sRGB output may be written through a raw 8-bit view (View::Raw).
        view_formats: if format == Format::Rgba8Srgb && ctx.info.backend != wgpu::Backend::Gl {
            &[wgpu::TextureFormat::Rgba8Unorm]
        } else {
            &[]
        },
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

/// Where the time of a job went.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct JobReport {
    pub adapter: String,
    pub backend: String,
    pub width: u32,
    pub height: u32,
    pub passes: Vec<PassTiming>,
    pub compile_ms: f64,
    pub decode_ms: f64,
    /// Waiting for the device after the decode (it is created meanwhile).
    pub device_ms: f64,
    /// Creating the device (on a thread, overlapping the decode); 0 with a given engine.
    pub device_created_ms: f64,
    pub pipeline_ms: f64,
    pub upload_ms: f64,
    pub passes_ms: f64,
    pub readback_ms: f64,
    pub encode_ms: f64,
    pub total_ms: f64,
    pub peak_bytes: u64,
    pub lower_bound_bytes: u64,
    pub naive_bytes: u64,
    /// Compiler warnings, rendered.
    #[serde(skip)]
    pub warnings: String,
    /// Compiler notes (informational: an automatic conversion), rendered.
    #[serde(skip)]
    pub notes: String,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Apply an effect chain to an image file and write the result atomically.
pub fn apply_to_image(
    job: &ImageJob,
    engine: Option<&mut Engine>,
    adapter: &super::context::AdapterChoice,
) -> Result<JobReport, RunError> {
    let t_all = Instant::now();
    let mut report = JobReport::default();
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
    std::thread::scope(|scope| -> Result<JobReport, RunError> {
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
        report.decode_ms = ms(t.elapsed());
        let t = Instant::now();
        drop(files);
        wait_device(&mut own_engine)?;
        // The time spent waiting for the device after the decode (its creation on
        // the thread is `device_created_ms`).
        report.device_ms = ms(t.elapsed());
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
    mut report: JobReport,
    t_all: Instant,
) -> Result<JobReport, RunError> {
    report.adapter = engine.ctx.info.name.clone();
    report.backend = format!("{:?}", engine.ctx.info.backend);
    let aux: Vec<(String, &Image)> = aux_imgs.iter().map(|(n, a)| (n.clone(), a)).collect();
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
    report.encode_ms = ms(t.elapsed());
    report.width = width;
    report.height = height;
    report.total_ms = ms(t_all.elapsed());
    Ok(report)
}

/// Apply an effect chain to an in-memory image on `engine`; returns the output
/// size and pixels read back in `out_format` (rgba8-srgb gives sRGB-encoded U8,
/// rgba16f/rgba32f give linear F32). Used by tests and Rust programs.
pub fn apply_in_memory(
    engine: &mut Engine,
    effects: &[String],
    overrides: &[String],
    img: &Image,
    aux: &[(String, &Image)],
    out_format: Format,
    assume_linear: bool,
) -> Result<(u32, u32, Pixels), RunError> {
    let mut effect = Effect::compile(effects, overrides)?;
    run_on_image(
        engine,
        &mut effect,
        img,
        aux,
        out_format,
        assume_linear,
        false,
        &mut JobReport::default(),
    )
}

/// Plan `effect` for `img`, upload it, run it once and read the output back,
/// recording the stage times (pipelines, upload, passes, readback) in `report`.
#[allow(clippy::too_many_arguments)]
fn run_on_image(
    engine: &mut Engine,
    effect: &mut Effect,
    img: &Image,
    aux: &[(String, &Image)],
    out_format: Format,
    assume_linear: bool,
    timings: bool,
    report: &mut JobReport,
) -> Result<(u32, u32, Pixels), RunError> {
    let (in_format, in_cs) = input_format(img, assume_linear);
    let desc = InputDesc {
        width: img.width,
        height: img.height,
        format: in_format,
        colorspace: in_cs,
        aux: aux
            .iter()
            .map(|(n, a)| (n.clone(), input_format(a, assume_linear).0))
            .collect(),
    };
    let t = Instant::now();
    let mut prepared = effect.prepare(engine, &desc, Some(out_format))?;
    report.pipeline_ms = ms(t.elapsed());
    report.peak_bytes = prepared.plan.peak_bytes;
    report.lower_bound_bytes = prepared.plan.lower_bound_bytes;
    report.naive_bytes = prepared.plan.naive_bytes;
    let t = Instant::now();
    let ctx = engine.ctx.clone();
    let input_tex = upload_image(&ctx, "fxgraph input", img, in_format)?;
    let aux_tex: Vec<(String, wgpu::Texture)> = aux
        .iter()
        .map(|(n, a)| {
            Ok((
                n.clone(),
                upload_image(
                    &ctx,
                    &format!("aux {n}"),
                    a,
                    input_format(a, assume_linear).0,
                )?,
            ))
        })
        .collect::<Result<_, GpuError>>()?;
    let out = prepared.plan.output;
    let output_tex = create_output(&ctx, out.width, out.height, out.format);
    report.upload_ms = ms(t.elapsed());
    let t = Instant::now();
    let mut inputs = FrameInputs::still(&input_tex, &prepared.plan);
    for (n, tex) in &aux_tex {
        inputs.aux.insert(n.clone(), tex.into());
    }
    report.passes = prepared.run(engine, &inputs, &output_tex, timings)?;
    report.passes_ms = ms(t.elapsed());
    let t = Instant::now();
    let pixels = read_pixels(&ctx, &output_tex, out.format)?;
    report.readback_ms = ms(t.elapsed());
    Ok((out.width, out.height, pixels))
}
