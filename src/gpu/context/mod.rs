//! The device layer: adapter selection, device creation, error scopes, texture
//! upload and readback, and GPU timing with timestamp queries.
//!
//! Everything here reports failures as [`GpuError`]; wgpu validation errors are
//! captured with error scopes ([`GpuContext::scoped`]) or, outside a scope, by the
//! uncaptured-error handler that [`GpuContext::new`] installs (it logs and records
//! them instead of panicking).

use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// Features requested when the adapter has them; never required.
///
/// `TIMESTAMP_QUERY` enables [`GpuTimer`], `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`
/// the adapter's own format capabilities (storage `r16f`, `rg16f`, `r8`, `rgb10a2`
/// for compute execution), `FLOAT32_FILTERABLE` linear sampling of 32-bit float
/// textures, `FLOAT32_BLENDABLE` blending into them and `PRIMITIVE_INDEX` the
/// renderer's visibility buffer (`@builtin(primitive_index)`).
const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::TIMESTAMP_QUERY
    .union(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
    .union(wgpu::Features::PIPELINE_CACHE)
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::FLOAT32_BLENDABLE)
    .union(wgpu::Features::ADDRESS_MODE_CLAMP_TO_BORDER)
    .union(wgpu::Features::PRIMITIVE_INDEX);

/// How many uncaptured errors [`GpuContext`] keeps for [`GpuContext::take_uncaptured_errors`].
const MAX_RECORDED_ERRORS: usize = 64;

/// How long a buffer mapping may take before [`GpuError::Map`] is returned.
const MAP_TIMEOUT: Duration = Duration::from_secs(120);

/// Errors of the device layer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter at all on the enabled backends.
    #[error("no GPU adapter found (backends tried: {tried}); set WGPU_BACKEND to choose others")]
    NoAdapter { tried: String },
    /// Adapters exist, but none matches the requested [`AdapterChoice`].
    #[error("no adapter matches {wanted}; available: {}", available.join("; "))]
    AdapterNotFound {
        wanted: String,
        available: Vec<String>,
    },
    /// `request_device` failed on every candidate adapter.
    #[error("could not create a device: {0}")]
    RequestDevice(String),
    /// A wgpu validation error captured while doing `what`.
    #[error("GPU validation error in {what}: {message}")]
    Validation { what: String, message: String },
    /// A wgpu internal error (e.g. a backend shader compiler failure) while doing `what`.
    #[error("GPU internal error in {what}: {message}")]
    Internal { what: String, message: String },
    /// The device ran out of memory while doing `what`.
    #[error("GPU out of memory in {what}")]
    OutOfMemory { what: String },
    /// A texture size is over the device limit.
    #[error("{what}: {width}x{height} exceeds the maximum texture size {max} of this device")]
    TooLarge {
        what: String,
        width: u32,
        height: u32,
        max: u32,
    },
    /// A texture format (or a usage of it) is not supported by the adapter.
    #[error("{what}: format {format} is not supported on {adapter}: {reason}")]
    UnsupportedFormat {
        what: String,
        format: String,
        adapter: String,
        reason: String,
    },
    /// Mapping a buffer for reading failed.
    #[error("buffer mapping failed: {0}")]
    Map(String),
    /// Waiting for the device failed (timeout or lost device).
    #[error("device poll failed: {0}")]
    Poll(String),
}

/// True when `FX_REQUIRE_GPU=1`: tests then fail instead of skipping when no adapter works.
pub fn require_gpu() -> bool {
    std::env::var("FX_REQUIRE_GPU").is_ok_and(|v| v.trim() == "1")
}

mod adapter;
mod error_text;
mod readback;
mod timer;

#[cfg(test)]
use adapter::preference;
use adapter::{
    auto_instance, backend_names, by_preference, create_instance, enumerate, request_device,
};
pub use adapter::{list_adapters, AdapterChoice, AdapterSummary};
pub(crate) use readback::map_read;
use readback::map_slice_read;
#[cfg(test)]
use readback::unpad_rows;
pub use readback::PendingReadback;
pub use timer::GpuTimer;

/// What a texture format can do on this device.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FormatSupport {
    /// Usable as a color render attachment.
    pub render: bool,
    /// Blendable when rendered to.
    pub blend: bool,
    /// Sampled with a filtering (linear) sampler.
    pub filter: bool,
    /// Usable as a storage texture.
    pub storage: bool,
}

/// A device and queue plus what the engine needs to know about them.
#[derive(Debug, Clone)]
pub struct GpuContext {
    /// The instance the adapter came from; `None` for [`GpuContext::from_existing`].
    pub instance: Option<wgpu::Instance>,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// The device has `TIMESTAMP_QUERY` (so [`GpuTimer`] works).
    pub timestamps: bool,
    /// The driver's pipeline cache, when one is attached
    /// ([`GpuContext::attach_pipeline_cache`]); the executor's pipelines use it.
    pub pipeline_cache: Option<wgpu::PipelineCache>,
    /// The backends enumerated to find the adapter (empty for
    /// [`GpuContext::from_existing`]): GL only when no native adapter exists.
    pub enumerated: wgpu::Backends,
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// The engine's fixed compute pipelines (Y'CbCr conversion), made once per
    /// device ([`GpuContext::compute_pipeline`]).
    compute_pipelines: Arc<Mutex<Vec<(String, CachedCompute)>>>,
}

/// A fixed compute pipeline and the layout of its bind group 0.
pub type CachedCompute = (wgpu::ComputePipeline, wgpu::BindGroupLayout);

/// The guarded value, also after a panic elsewhere poisoned the lock (the data
/// is a cache: never half written).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl GpuContext {
    /// Picks an adapter and creates a device on it.
    ///
    /// With [`AdapterChoice::Auto`] a real discrete/integrated GPU is preferred, then
    /// Vulkan on the CPU (lavapipe), then GL (llvmpipe); if creating a device fails
    /// the next candidate is tried. The device gets the adapter's own limits and the
    /// optional features (`TIMESTAMP_QUERY`, `FLOAT32_FILTERABLE`, `FLOAT32_BLENDABLE`)
    /// that the adapter has. An uncaptured-error handler is installed that logs and
    /// records errors (see [`GpuContext::take_uncaptured_errors`]) instead of panicking.
    pub fn new(choice: &AdapterChoice) -> Result<Self, GpuError> {
        let start = Instant::now();
        let (instance, backends, adapters) = match choice {
            AdapterChoice::Auto => auto_instance(),
            // An index or a name refers to the full list (`--adapters`).
            _ => {
                let (instance, backends) = create_instance();
                let adapters = enumerate(&instance);
                (instance, backends, adapters)
            }
        };
        if adapters.is_empty() {
            return Err(GpuError::NoAdapter {
                tried: backend_names(backends),
            });
        }
        let not_found = |adapters: &[wgpu::Adapter]| GpuError::AdapterNotFound {
            wanted: choice.to_string(),
            available: adapters
                .iter()
                .enumerate()
                .map(|(i, a)| AdapterSummary::new(i, a).to_string())
                .collect(),
        };
        let candidates: Vec<&wgpu::Adapter> = match choice {
            AdapterChoice::Auto => by_preference(adapters.iter()),
            AdapterChoice::Index(i) => {
                vec![adapters.get(*i).ok_or_else(|| not_found(&adapters))?]
            }
            AdapterChoice::NameContains(fragment) => {
                let fragment = fragment.to_lowercase();
                let matching = by_preference(
                    adapters
                        .iter()
                        .filter(|a| a.get_info().name.to_lowercase().contains(&fragment)),
                );
                if matching.is_empty() {
                    return Err(not_found(&adapters));
                }
                matching
            }
        };

        let mut failures = Vec::new();
        for adapter in candidates {
            let info = adapter.get_info();
            match request_device(adapter) {
                Ok((device, queue)) => {
                    let mut ctx = Self::assemble(Some(instance), adapter.clone(), device, queue);
                    ctx.enumerated = backends;
                    ctx.install_error_handler();
                    log::info!(
                        "GPU: {} ({}, {:?}, {} {}); timestamps {}; max texture {}; created in {:.1} ms",
                        ctx.info.name,
                        ctx.info.backend,
                        ctx.info.device_type,
                        ctx.info.driver,
                        ctx.info.driver_info,
                        ctx.timestamps,
                        ctx.device.limits().max_texture_dimension_2d,
                        start.elapsed().as_secs_f64() * 1e3
                    );
                    return Ok(ctx);
                }
                Err(e) => {
                    log::warn!(
                        "could not create a device on {} ({}): {e}",
                        info.name,
                        info.backend
                    );
                    failures.push(format!("{} ({}): {e}", info.name, info.backend));
                }
            }
        }
        Err(GpuError::RequestDevice(failures.join("; ")))
    }

    /// Wraps a device and queue created by the caller.
    ///
    /// The caller's uncaptured-error handler is left alone (wgpu's default one panics);
    /// call [`GpuContext::install_error_handler`] to use ours instead.
    pub fn from_existing(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        Self::assemble(None, adapter, device, queue)
    }

    fn assemble(
        instance: Option<wgpu::Instance>,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        let info = adapter.get_info();
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        GpuContext {
            instance,
            adapter,
            device,
            queue,
            info,
            timestamps,
            enumerated: wgpu::Backends::empty(),
            pipeline_cache: None,
            uncaptured: Arc::default(),
            compute_pipelines: Arc::default(),
        }
    }

    /// The compute pipeline `label` (entry point `main`, layout from the shader)
    /// of WGSL `source`, made on first use and kept for the device's life: the
    /// engine's fixed passes are compiled once however many converters are made
    /// (a JIT compile costs 50-100 ms on lavapipe).
    pub fn compute_pipeline(&self, label: &str, source: &str) -> Result<CachedCompute, GpuError> {
        let key = format!("{label}\n{source}");
        if let Some((_, hit)) = lock(&self.compute_pipelines)
            .iter()
            .find(|(k, _)| *k == key)
        {
            return Ok(hit.clone());
        }
        let made = self.scoped(label, |device| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: self.pipeline_cache.as_ref(),
            });
            let layout = pipeline.get_bind_group_layout(0);
            (pipeline, layout)
        })?;
        lock(&self.compute_pipelines).push((key, made.clone()));
        Ok(made)
    }

    /// Whether the device has wgpu's `PIPELINE_CACHE` feature (Vulkan).
    pub fn has_pipeline_cache_feature(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::PIPELINE_CACHE)
    }

    /// wgpu's name for the pipeline cache data of this adapter and driver.
    pub fn pipeline_cache_key(&self) -> Option<String> {
        wgpu::util::pipeline_cache_key(&self.info)
    }

    /// Attach a pipeline cache, seeded with `data` from
    /// [`GpuContext::pipeline_cache_data`] of an earlier device on the same
    /// adapter and driver (the caller keeps it, e.g. in a file); data the driver
    /// does not accept starts an empty cache. No effect without the feature.
    pub fn attach_pipeline_cache(&mut self, data: Option<&[u8]>) {
        if !self.has_pipeline_cache_feature() {
            return;
        }
        // SAFETY: wgpu requires `data` to come from `PipelineCache::get_data` of
        // this adapter; callers key it by `pipeline_cache_key` (adapter and
        // driver), the driver validates the header, and `fallback` makes an
        // empty cache of data it rejects.
        let cache = unsafe {
            self.device
                .create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                    label: Some("fxgraph pipeline cache"),
                    data,
                    fallback: true,
                })
        };
        self.pipeline_cache = Some(cache);
    }

    /// The attached pipeline cache's data, to seed the next device with.
    pub fn pipeline_cache_data(&self) -> Option<Vec<u8>> {
        self.pipeline_cache.as_ref().and_then(|c| c.get_data())
    }

    /// Installs the handler that logs and records errors raised outside [`GpuContext::scoped`]
    /// (replacing any previous handler), and a device-lost callback that logs.
    pub fn install_error_handler(&self) {
        let sink = Arc::clone(&self.uncaptured);
        self.device
            .on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
                let message = error_text::wgpu_error_text(&error);
                log::error!("uncaptured GPU error: {message}");
                let mut errors = sink.lock().unwrap_or_else(|e| e.into_inner());
                if errors.len() >= MAX_RECORDED_ERRORS {
                    errors.remove(0);
                }
                errors.push(message);
            }));
        self.device
            .set_device_lost_callback(|reason, message| match reason {
                wgpu::DeviceLostReason::Destroyed => log::debug!("GPU device destroyed"),
                _ => log::error!("GPU device lost ({reason:?}): {message}"),
            });
    }

    /// Errors recorded by the uncaptured-error handler since the last call (oldest first,
    /// at most the last 64).
    pub fn take_uncaptured_errors(&self) -> Vec<String> {
        std::mem::take(&mut *self.uncaptured.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// Runs `f` inside validation, out-of-memory and internal error scopes; the first
    /// captured error becomes a [`GpuError`] naming `label`.
    ///
    /// Error scopes are per thread and popped in LIFO order, so `f` must not leave
    /// scopes of its own pushed; errors of work done on other threads are not captured.
    pub fn scoped<T>(
        &self,
        label: &str,
        f: impl FnOnce(&wgpu::Device) -> T,
    ) -> Result<T, GpuError> {
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let value = f(&self.device);
        // The futures are ready at once on native; `pop` itself takes effect immediately.
        let internal = pollster::block_on(internal.pop());
        let oom = pollster::block_on(oom.pop());
        let validation = pollster::block_on(validation.pop());
        let what = label.to_string();
        if let Some(error) = validation {
            log::debug!("validation error in {label}: {error}");
            return Err(GpuError::Validation {
                what,
                message: error_text::wgpu_error_text(&error),
            });
        }
        if let Some(error) = internal {
            log::debug!("internal error in {label}: {error}");
            return Err(GpuError::Internal {
                what,
                message: error_text::wgpu_error_text(&error),
            });
        }
        if oom.is_some() {
            return Err(GpuError::OutOfMemory { what });
        }
        Ok(value)
    }

    /// The format features the device validates against: the adapter's own when the
    /// device is downlevel (GL) or has `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`, the
    /// WebGPU-guaranteed ones otherwise (this mirrors wgpu-core).
    pub fn format_features(&self, format: wgpu::TextureFormat) -> wgpu::TextureFormatFeatures {
        let features = self.device.features();
        if !features.contains(format.required_features()) {
            return wgpu::TextureFormatFeatures {
                allowed_usages: wgpu::TextureUsages::empty(),
                flags: wgpu::TextureFormatFeatureFlags::empty(),
            };
        }
        let adapter_specific =
            features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        let downlevel = !self
            .adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::WEBGPU_TEXTURE_FORMAT_SUPPORT);
        if adapter_specific || downlevel {
            let mut supported = self.adapter.get_texture_format_features(format);
            let float32 = matches!(
                format,
                wgpu::TextureFormat::R32Float
                    | wgpu::TextureFormat::Rg32Float
                    | wgpu::TextureFormat::Rgba32Float
            );
            if float32 && !features.contains(wgpu::Features::FLOAT32_FILTERABLE) {
                supported
                    .flags
                    .remove(wgpu::TextureFormatFeatureFlags::FILTERABLE);
            }
            supported
        } else {
            format.guaranteed_format_features(features)
        }
    }

    /// Can `format` be rendered to (and blended), sampled with filtering, or used as a
    /// storage texture on this device?
    pub fn format_support(&self, format: wgpu::TextureFormat) -> FormatSupport {
        let features = self.format_features(format);
        let usages = features.allowed_usages;
        let flags = features.flags;
        let render = format.has_color_aspect()
            && !format.is_depth_stencil_format()
            && usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT);
        FormatSupport {
            render,
            blend: render && flags.contains(wgpu::TextureFormatFeatureFlags::BLENDABLE),
            filter: usages.contains(wgpu::TextureUsages::TEXTURE_BINDING)
                && flags.contains(wgpu::TextureFormatFeatureFlags::FILTERABLE),
            storage: usages.contains(wgpu::TextureUsages::STORAGE_BINDING),
        }
    }

    /// Checks a 2D texture size against the device limit; `what` names the texture.
    pub fn check_size(&self, width: u32, height: u32, what: &str) -> Result<(), GpuError> {
        if width == 0 || height == 0 {
            return Err(GpuError::Validation {
                what: what.to_string(),
                message: format!("texture size {width}x{height} is empty"),
            });
        }
        let max = self.device.limits().max_texture_dimension_2d;
        if width > max || height > max {
            return Err(GpuError::TooLarge {
                what: what.to_string(),
                width,
                height,
                max,
            });
        }
        Ok(())
    }

    /// Creates a 2D texture and uploads tightly packed rows (`width * texel size` bytes
    /// each; `queue.write_texture` needs no 256-byte row alignment).
    ///
    /// Works for any uncompressed color format; `data` is the raw texel bytes
    /// (`u8` for `Rgba8*`, `half::f16` for `Rgba16Float`, `f32` for `Rgba32Float`).
    /// The usage is `TEXTURE_BINDING | COPY_DST | COPY_SRC | usage_extra`. For formats
    /// with an sRGB twin (`Rgba8Unorm` / `Rgba8UnormSrgb`, ...) the twin is added to
    /// `view_formats` when the device supports view formats (not on GL).
    pub fn upload_texture(
        &self,
        label: &str,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
        data: &[u8],
        usage_extra: wgpu::TextureUsages,
    ) -> Result<wgpu::Texture, GpuError> {
        self.check_size(width, height, label)?;
        let texel = self.texel_size(format, label)?;
        let row = width * texel;
        let expected = u64::from(row) * u64::from(height);
        if data.len() as u64 != expected {
            return Err(GpuError::Validation {
                what: label.to_string(),
                message: format!(
                    "upload data is {} bytes, expected {expected} ({width}x{height} {format:?}, {texel} bytes per texel)",
                    data.len()
                ),
            });
        }
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC
            | usage_extra;
        self.check_usage(format, usage, label)?;
        let twin = self.srgb_twin(format);
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        self.scoped(label, |device| {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: twin.as_slice(),
            });
            self.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                data,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(height),
                },
                size,
            );
            texture
        })
    }

    /// Reads mip 0, layer 0 of `texture` back as tightly packed rows; blocks until done.
    ///
    /// The texture needs `COPY_SRC` usage and an uncompressed color format.
    pub fn read_texture(&self, texture: &wgpu::Texture) -> Result<Vec<u8>, GpuError> {
        let pending = self.scoped("texture readback", |device| {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("fxgraph readback encoder"),
            });
            let pending = self.encode_readback(&mut encoder, texture)?;
            self.queue.submit([encoder.finish()]);
            Ok::<_, GpuError>(pending)
        })??;
        pending.finish()
    }

    /// Encodes a copy of mip 0, layer 0 of `texture` into a padded buffer; after the
    /// encoder is submitted, [`PendingReadback::finish`] maps it and returns tight rows.
    ///
    /// Fails early when the texture cannot be copied (no `COPY_SRC`, multisampled,
    /// compressed, depth/stencil).
    pub fn encode_readback(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Result<PendingReadback, GpuError> {
        const WHAT: &str = "texture readback";
        let format = texture.format();
        let texel = self.texel_size(format, WHAT)?;
        if !texture.usage().contains(wgpu::TextureUsages::COPY_SRC) {
            return Err(GpuError::Validation {
                what: WHAT.to_string(),
                message: format!(
                    "texture ({}x{} {format:?}) lacks COPY_SRC usage (has {:?})",
                    texture.width(),
                    texture.height(),
                    texture.usage()
                ),
            });
        }
        if texture.sample_count() > 1 {
            return Err(GpuError::Validation {
                what: WHAT.to_string(),
                message: format!(
                    "a multisampled texture ({} samples) cannot be copied; resolve it first",
                    texture.sample_count()
                ),
            });
        }
        let (width, height) = (texture.width(), texture.height());
        let unpadded_bytes_per_row = width * texel;
        let padded_bytes_per_row = unpadded_bytes_per_row
            .div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fxgraph readback buffer"),
            size: u64::from(padded_bytes_per_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_bytes_per_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        Ok(PendingReadback {
            device: self.device.clone(),
            buffer,
            width,
            height,
            format,
            unpadded_bytes_per_row,
            padded_bytes_per_row,
        })
    }

    /// Blocks until all submitted work has finished.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(drop)
            .map_err(|e| GpuError::Poll(e.to_string()))
    }

    /// Bytes per texel of an uncompressed single-aspect color format.
    fn texel_size(&self, format: wgpu::TextureFormat, what: &str) -> Result<u32, GpuError> {
        let unsupported = |reason: &str| GpuError::UnsupportedFormat {
            what: what.to_string(),
            format: format!("{format:?}"),
            adapter: self.info.name.clone(),
            reason: reason.to_string(),
        };
        if format.is_depth_stencil_format() || !format.has_color_aspect() {
            return Err(unsupported("only color formats are supported here"));
        }
        if format.block_dimensions() != (1, 1) {
            return Err(unsupported("compressed formats are not supported here"));
        }
        format
            .block_copy_size(None)
            .ok_or_else(|| unsupported("the format has no single texel size (planar?)"))
    }

    fn check_usage(
        &self,
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
        what: &str,
    ) -> Result<(), GpuError> {
        let allowed = self.format_features(format).allowed_usages;
        if allowed.contains(usage) {
            return Ok(());
        }
        Err(GpuError::UnsupportedFormat {
            what: what.to_string(),
            format: format!("{format:?}"),
            adapter: self.info.name.clone(),
            reason: format!(
                "usage {:?} is not allowed (allowed: {allowed:?})",
                usage.difference(allowed)
            ),
        })
    }

    /// The sRGB/linear twin of `format` for `view_formats`, if it has one and the
    /// device can create views in another format.
    pub(crate) fn srgb_twin(&self, format: wgpu::TextureFormat) -> Option<wgpu::TextureFormat> {
        let twin = if format.is_srgb() {
            format.remove_srgb_suffix()
        } else {
            format.add_srgb_suffix()
        };
        if twin == format {
            return None;
        }
        let view_formats = self
            .adapter
            .get_downlevel_capabilities()
            .flags
            .contains(wgpu::DownlevelFlags::VIEW_FORMATS);
        if !view_formats {
            log::debug!("{format:?}: no {twin:?} view format (device lacks VIEW_FORMATS)");
            return None;
        }
        Some(twin)
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unpad_removes_padding() {
        let data: Vec<u8> = (0..12).collect();
        assert_eq!(unpad_rows(&data, 2, 4, 3), vec![0, 1, 4, 5, 8, 9]);
        assert_eq!(unpad_rows(&data, 4, 4, 2), vec![0, 1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn adapter_choice_parses() {
        assert_eq!("".parse::<AdapterChoice>(), Ok(AdapterChoice::Auto));
        assert_eq!("Auto".parse::<AdapterChoice>(), Ok(AdapterChoice::Auto));
        assert_eq!("2".parse::<AdapterChoice>(), Ok(AdapterChoice::Index(2)));
        assert_eq!(
            "llvmpipe".parse::<AdapterChoice>(),
            Ok(AdapterChoice::NameContains("llvmpipe".into()))
        );
    }

    #[test]
    fn preference_orders_real_gpus_then_lavapipe_then_gl() {
        let info = wgpu::AdapterInfo::new;
        let discrete_gl = preference(&info(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Gl));
        let lavapipe = preference(&info(wgpu::DeviceType::Cpu, wgpu::Backend::Vulkan));
        let llvmpipe_gl = preference(&info(wgpu::DeviceType::Cpu, wgpu::Backend::Gl));
        let integrated_vk = preference(&info(
            wgpu::DeviceType::IntegratedGpu,
            wgpu::Backend::Vulkan,
        ));
        assert!(integrated_vk < lavapipe);
        assert!(discrete_gl < lavapipe);
        assert!(lavapipe < llvmpipe_gl);
    }
}
