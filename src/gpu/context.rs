//! The device layer: adapter selection, device creation, error scopes, texture
//! upload and readback, and GPU timing with timestamp queries.
//!
//! Everything here reports failures as [`GpuError`]; wgpu validation errors are
//! captured with error scopes ([`GpuContext::scoped`]) or, outside a scope, by the
//! uncaptured-error handler that [`GpuContext::new`] installs (it logs and records
//! them instead of panicking).

use std::fmt;
use std::str::FromStr;
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// Features requested when the adapter has them; never required.
///
/// `TIMESTAMP_QUERY` enables [`GpuTimer`], `FLOAT32_FILTERABLE` linear sampling of
/// 32-bit float textures and `FLOAT32_BLENDABLE` blending into them.
const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::TIMESTAMP_QUERY
    .union(wgpu::Features::FLOAT32_FILTERABLE)
    .union(wgpu::Features::FLOAT32_BLENDABLE);

/// How many uncaptured errors [`GpuContext`] keeps for [`GpuContext::take_uncaptured_errors`].
const MAX_RECORDED_ERRORS: usize = 64;

/// How long a buffer mapping may take before [`GpuError::Map`] is returned.
const MAP_TIMEOUT: Duration = Duration::from_secs(120);

/// Errors of the device layer.
#[derive(Debug, thiserror::Error)]
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

/// Which adapter [`GpuContext::new`] uses.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum AdapterChoice {
    /// A real discrete/integrated GPU first, then Vulkan on the CPU (lavapipe), then GL.
    #[default]
    Auto,
    /// The adapter at this position in [`list_adapters`].
    Index(usize),
    /// The preferred adapter whose name contains this text (case-insensitive).
    NameContains(String),
}

impl FromStr for AdapterChoice {
    type Err = std::convert::Infallible;

    /// `"auto"` (or empty), a number (an index into [`list_adapters`]), or a name fragment.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        Ok(if s.is_empty() || s.eq_ignore_ascii_case("auto") {
            AdapterChoice::Auto
        } else if let Ok(index) = s.parse() {
            AdapterChoice::Index(index)
        } else {
            AdapterChoice::NameContains(s.to_string())
        })
    }
}

impl fmt::Display for AdapterChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AdapterChoice::Auto => f.write_str("auto"),
            AdapterChoice::Index(i) => write!(f, "adapter index {i}"),
            AdapterChoice::NameContains(name) => write!(f, "adapter name containing {name:?}"),
        }
    }
}

/// One adapter as seen by [`list_adapters`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdapterSummary {
    /// Position in [`list_adapters`]; usable with [`AdapterChoice::Index`].
    pub index: usize,
    pub name: String,
    /// `vulkan`, `gl`, `metal`, `dx12`.
    pub backend: String,
    /// `DiscreteGpu`, `IntegratedGpu`, `VirtualGpu`, `Cpu` or `Other`.
    pub device_type: String,
    /// Driver name and driver info.
    pub driver: String,
    /// Whether the adapter supports timestamp queries.
    pub timestamps: bool,
}

impl AdapterSummary {
    fn new(index: usize, adapter: &wgpu::Adapter) -> Self {
        let info = adapter.get_info();
        let driver = [info.driver.trim(), info.driver_info.trim()]
            .iter()
            .filter(|s| !s.is_empty())
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        AdapterSummary {
            index,
            name: info.name,
            backend: info.backend.to_str().to_string(),
            device_type: format!("{:?}", info.device_type),
            driver,
            timestamps: adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY),
        }
    }
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[{}] {} ({}, {}",
            self.index, self.name, self.backend, self.device_type
        )?;
        if !self.driver.is_empty() {
            write!(f, ", {}", self.driver)?;
        }
        if self.timestamps {
            f.write_str(", timestamps")?;
        }
        f.write_str(")")
    }
}

/// Every adapter on every enabled backend (`WGPU_BACKEND` restricts them; default all).
pub fn list_adapters() -> Vec<AdapterSummary> {
    let (instance, _) = create_instance();
    enumerate(&instance)
        .iter()
        .enumerate()
        .map(|(i, a)| AdapterSummary::new(i, a))
        .collect()
}

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
    uncaptured: Arc<Mutex<Vec<String>>>,
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
        let (instance, backends) = create_instance();
        let adapters = enumerate(&instance);
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
                    let ctx = Self::assemble(Some(instance), adapter.clone(), device, queue);
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
            uncaptured: Arc::default(),
        }
    }

    /// Installs the handler that logs and records errors raised outside [`GpuContext::scoped`]
    /// (replacing any previous handler), and a device-lost callback that logs.
    pub fn install_error_handler(&self) {
        let sink = Arc::clone(&self.uncaptured);
        self.device
            .on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
                let message = error.to_string();
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
                message: error.to_string(),
            });
        }
        if let Some(error) = internal {
            log::debug!("internal error in {label}: {error}");
            return Err(GpuError::Internal {
                what,
                message: error.to_string(),
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
    fn srgb_twin(&self, format: wgpu::TextureFormat) -> Option<wgpu::TextureFormat> {
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

/// A texture copy encoded by [`GpuContext::encode_readback`], waiting to be read.
#[derive(Debug)]
pub struct PendingReadback {
    device: wgpu::Device,
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    unpadded_bytes_per_row: u32,
    padded_bytes_per_row: u32,
}

impl PendingReadback {
    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Maps the buffer, waits for the copy and returns tightly packed rows.
    ///
    /// Call it only after the encoder holding the copy has been submitted.
    pub fn finish(self) -> Result<Vec<u8>, GpuError> {
        map_read(&self.device, &self.buffer)?;
        let out = {
            let mapped = self
                .buffer
                .get_mapped_range(..)
                .map_err(|e| GpuError::Map(e.to_string()))?;
            unpad_rows(
                &mapped,
                self.unpadded_bytes_per_row as usize,
                self.padded_bytes_per_row as usize,
                self.height as usize,
            )
        };
        self.buffer.unmap();
        Ok(out)
    }
}

/// GPU pass timing with timestamp queries: one begin/end pair per pass.
///
/// Use [`GpuTimer::pass_writes`] in each render pass, [`GpuTimer::resolve`] at the end
/// of the encoder, submit, then [`GpuTimer::read_ms`].
#[derive(Debug)]
pub struct GpuTimer {
    query_set: wgpu::QuerySet,
    resolve_buffer: wgpu::Buffer,
    readback_buffer: wgpu::Buffer,
    max_passes: u32,
}

impl GpuTimer {
    /// `None` when the device has no timestamp queries, `max_passes` is 0, or creating
    /// the query set fails. `max_passes` is capped at `QUERY_SET_MAX_QUERIES / 2`.
    pub fn new(ctx: &GpuContext, max_passes: u32) -> Option<Self> {
        if !ctx.timestamps || max_passes == 0 {
            return None;
        }
        let cap = wgpu::QUERY_SET_MAX_QUERIES / 2;
        if max_passes > cap {
            log::warn!("GPU timer: {max_passes} passes requested, timing only the first {cap}");
        }
        let max_passes = max_passes.min(cap);
        let bytes = u64::from(max_passes) * 2 * u64::from(wgpu::QUERY_SIZE);
        let created = ctx.scoped("GPU timer", |device| {
            let query_set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fxgraph pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: max_passes * 2,
            });
            let resolve_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fxgraph timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback_buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fxgraph timestamp readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            GpuTimer {
                query_set,
                resolve_buffer,
                readback_buffer,
                max_passes,
            }
        });
        created
            .inspect_err(|e| log::warn!("GPU timing disabled: {e}"))
            .ok()
    }

    /// How many passes this timer can time.
    pub fn max_passes(&self) -> u32 {
        self.max_passes
    }

    /// Timestamp writes for pass `i` (`None` when `i >= max_passes`).
    pub fn pass_writes(&self, i: u32) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        (i < self.max_passes).then(|| wgpu::RenderPassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Timestamp writes for compute pass `i` (`None` when `i >= max_passes`).
    pub fn compute_pass_writes(&self, i: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        (i < self.max_passes).then(|| wgpu::ComputePassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Resolves the first `used` passes' timestamps and copies them to the readback
    /// buffer; encode it after the timed passes.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder, used: u32) {
        let used = used.min(self.max_passes);
        if used == 0 {
            return;
        }
        encoder.resolve_query_set(&self.query_set, 0..2 * used, &self.resolve_buffer, 0);
        encoder.copy_buffer_to_buffer(
            &self.resolve_buffer,
            0,
            &self.readback_buffer,
            0,
            u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE),
        );
    }

    /// Milliseconds of the first `used` passes; call after the encoder with
    /// [`GpuTimer::resolve`] was submitted. Blocks until the GPU is done.
    pub fn read_ms(&self, ctx: &GpuContext, used: u32) -> Result<Vec<f64>, GpuError> {
        let used = used.min(self.max_passes);
        if used == 0 {
            return Ok(Vec::new());
        }
        let bytes = u64::from(used) * 2 * u64::from(wgpu::QUERY_SIZE);
        let slice = self.readback_buffer.slice(..bytes);
        map_slice_read(&ctx.device, &slice)?;
        let ticks: Vec<u64> = {
            let mapped = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Map(e.to_string()))?;
            mapped
                .chunks_exact(8)
                .map(bytemuck::pod_read_unaligned::<u64>)
                .collect()
        };
        self.readback_buffer.unmap();
        let period_ns = f64::from(ctx.queue.get_timestamp_period());
        Ok(ticks
            .chunks_exact(2)
            .map(|pair| pair[1].saturating_sub(pair[0]) as f64 * period_ns / 1e6)
            .collect())
    }
}

/// An instance configured from the environment (`WGPU_BACKEND`, `WGPU_DEBUG`, ...);
/// all backends when `WGPU_BACKEND` is unset or blank.
fn create_instance() -> (wgpu::Instance, wgpu::Backends) {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    if std::env::var("WGPU_BACKEND").is_ok_and(|v| v.trim().is_empty()) {
        // wgpu reads a blank value as "no backends"; treat it as unset.
        desc.backends = wgpu::Backends::all();
    }
    let backends = desc.backends & wgpu::Instance::enabled_backend_features();
    log::debug!("wgpu instance backends: {}", backend_names(backends));
    (wgpu::Instance::new(desc), backends)
}

fn backend_names(backends: wgpu::Backends) -> String {
    let names: Vec<&str> = backends.iter_names().map(|(name, _)| name).collect();
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}

/// Adapters in enumeration order (the order [`AdapterChoice::Index`] refers to).
fn enumerate(instance: &wgpu::Instance) -> Vec<wgpu::Adapter> {
    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()))
        .into_iter()
        .filter(|a| {
            !matches!(
                a.get_info().backend,
                wgpu::Backend::Noop | wgpu::Backend::BrowserWebGpu
            )
        })
        .collect()
}

/// Sorts adapters by the Auto preference; stable, so ties keep enumeration order.
fn by_preference<'a>(adapters: impl Iterator<Item = &'a wgpu::Adapter>) -> Vec<&'a wgpu::Adapter> {
    let mut ranked: Vec<_> = adapters.map(|a| (preference(&a.get_info()), a)).collect();
    ranked.sort_by_key(|(rank, _)| *rank);
    ranked.into_iter().map(|(_, a)| a).collect()
}

/// Lower is better: device type first (real GPUs, then CPU), then backend.
fn preference(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let device = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    let backend = match info.backend {
        wgpu::Backend::Vulkan => 0,
        wgpu::Backend::Metal => 1,
        wgpu::Backend::Dx12 => 2,
        wgpu::Backend::Gl => 3,
        _ => 4,
    };
    (device, backend)
}

fn request_device(
    adapter: &wgpu::Adapter,
) -> Result<(wgpu::Device, wgpu::Queue), wgpu::RequestDeviceError> {
    let features = adapter.features() & OPTIONAL_FEATURES;
    pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("fxgraph device"),
        required_features: features,
        required_limits: adapter.limits(),
        ..Default::default()
    }))
}

fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<(), GpuError> {
    map_slice_read(device, &buffer.slice(..))
}

/// Maps `slice` for reading and waits for it, polling the device.
fn map_slice_read(device: &wgpu::Device, slice: &wgpu::BufferSlice<'_>) -> Result<(), GpuError> {
    let (tx, rx) = mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver only goes away when we gave up waiting.
        let _ = tx.send(result);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Poll(e.to_string()))?;
    let deadline = Instant::now() + MAP_TIMEOUT;
    loop {
        match rx.try_recv() {
            Ok(result) => return result.map_err(|e| GpuError::Map(e.to_string())),
            Err(mpsc::TryRecvError::Disconnected) => {
                return Err(GpuError::Map("the map callback was dropped".to_string()))
            }
            // Another thread may be polling and running our callback; keep polling.
            Err(mpsc::TryRecvError::Empty) if Instant::now() < deadline => {
                device
                    .poll(wgpu::PollType::Poll)
                    .map_err(|e| GpuError::Poll(e.to_string()))?;
                std::thread::sleep(Duration::from_millis(1));
            }
            Err(mpsc::TryRecvError::Empty) => {
                return Err(GpuError::Map(format!(
                    "timed out after {} s waiting for the buffer mapping",
                    MAP_TIMEOUT.as_secs()
                )))
            }
        }
    }
}

/// Drops the row padding of a buffer copied with `padded` bytes per row.
fn unpad_rows(data: &[u8], unpadded: usize, padded: usize, rows: usize) -> Vec<u8> {
    if unpadded == padded {
        return data[..unpadded * rows].to_vec();
    }
    let mut out = Vec::with_capacity(unpadded * rows);
    for row in data.chunks(padded).take(rows) {
        out.extend_from_slice(&row[..unpadded]);
    }
    out
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
