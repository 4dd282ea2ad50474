//! Adapters: choosing one (`--adapter`), listing them, creating the device.

use super::*;
use std::fmt;
use std::str::FromStr;

/// Which adapter [`GpuContext::new`] uses.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
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
    pub(super) fn new(index: usize, adapter: &wgpu::Adapter) -> Self {
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
/// An instance configured from the environment (`WGPU_BACKEND`, `WGPU_DEBUG`, ...);
/// all backends when `WGPU_BACKEND` is unset or blank.
pub(super) fn create_instance() -> (wgpu::Instance, wgpu::Backends) {
    let (_, backends) = backends_from_env();
    create_instance_with(backends)
}

/// The instance and adapters [`AdapterChoice::Auto`] chooses from: the native
/// backends (Vulkan, Metal, DX12) first, and GL only when none of them has an
/// adapter. Creating a GL instance and enumerating its adapters (EGL, often
/// llvmpipe) costs tens of milliseconds of every run and never wins the Auto
/// preference over a native adapter. `WGPU_BACKEND` still restricts the backends.
pub(super) fn auto_instance() -> (wgpu::Instance, wgpu::Backends, Vec<wgpu::Adapter>) {
    let (_, wanted) = backends_from_env();
    let native = wanted & !wgpu::Backends::GL;
    if !native.is_empty() && native != wanted {
        let (instance, backends) = create_instance_with(native);
        let adapters = enumerate(&instance);
        if !adapters.is_empty() {
            return (instance, backends, adapters);
        }
        log::debug!("no adapter on {}; trying GL", backend_names(native));
    }
    let (instance, backends) = create_instance();
    let adapters = enumerate(&instance);
    (instance, backends, adapters)
}

/// The instance descriptor from the environment and the backends it enables.
fn backends_from_env() -> (wgpu::InstanceDescriptor, wgpu::Backends) {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    if std::env::var("WGPU_BACKEND").is_ok_and(|v| v.trim().is_empty()) {
        // wgpu reads a blank value as "no backends"; treat it as unset.
        desc.backends = wgpu::Backends::all();
    }
    let backends = desc.backends & wgpu::Instance::enabled_backend_features();
    (desc, backends)
}

/// An instance configured from the environment, on `backends` only.
fn create_instance_with(backends: wgpu::Backends) -> (wgpu::Instance, wgpu::Backends) {
    let (mut desc, _) = backends_from_env();
    desc.backends = backends;
    log::debug!("wgpu instance backends: {}", backend_names(backends));
    (wgpu::Instance::new(desc), backends)
}

pub(super) fn backend_names(backends: wgpu::Backends) -> String {
    let names: Vec<&str> = backends.iter_names().map(|(name, _)| name).collect();
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}

/// Adapters in enumeration order (the order [`AdapterChoice::Index`] refers to).
pub(super) fn enumerate(instance: &wgpu::Instance) -> Vec<wgpu::Adapter> {
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
pub(super) fn by_preference<'a>(
    adapters: impl Iterator<Item = &'a wgpu::Adapter>,
) -> Vec<&'a wgpu::Adapter> {
    let mut ranked: Vec<_> = adapters.map(|a| (preference(&a.get_info()), a)).collect();
    ranked.sort_by_key(|(rank, _)| *rank);
    ranked.into_iter().map(|(_, a)| a).collect()
}

/// Lower is better: device type first (real GPUs, then CPU), then backend.
pub(super) fn preference(info: &wgpu::AdapterInfo) -> (u8, u8) {
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

pub(super) fn request_device(
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
