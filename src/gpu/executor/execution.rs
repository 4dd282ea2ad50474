//! Which path runs a pass: a full-screen fragment pass or a compute dispatch
//! (docs/architecture.md, "Execution paths"), and the rule `auto` applies.

use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicU8, Ordering};

/// How an [`Engine`](super::Engine) runs the passes of an effect.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum Execution {
    /// Chosen per adapter by [`Execution::resolve`].
    #[default]
    Auto,
    /// Every pass is a full-screen fragment pass.
    Fragment,
    /// Every pass the compute stage can run is a compute dispatch; the others
    /// (a target format the adapter cannot store to, a shader using derivatives
    /// or `discard`, a BGRA window surface) stay fragment passes.
    Compute,
}

impl Execution {
    /// The path `auto` takes on an adapter:
    ///
    /// - a CPU adapter (lavapipe, llvmpipe, SwiftShader): **fragment**. There the
    ///   two paths cost the same for long passes (1080p 49-tap blur: fragment
    ///   231 ms, compute 240 ms on lavapipe, `../shared/perf/README.md`), and
    ///   fragment keeps the figures every earlier benchmark measured;
    /// - the GL backend: **fragment** (GL's storage-image formats are few);
    /// - any other GPU on Vulkan, Metal or DX12: **compute**. On an NVIDIA H200 the
    ///   same WGSL ran 23× faster as a compute dispatch for a copy and 18× for a
    ///   49-tap blur, because rasterisation uses a small part of such chips;
    ///   consumer GPUs rasterise at full width, and compute is not slower there.
    pub fn resolve(self, info: &wgpu::AdapterInfo) -> Execution {
        match self {
            Execution::Auto => {
                if info.device_type == wgpu::DeviceType::Cpu || info.backend == wgpu::Backend::Gl {
                    Execution::Fragment
                } else {
                    Execution::Compute
                }
            }
            other => other,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Execution::Auto => "auto",
            Execution::Fragment => "fragment",
            Execution::Compute => "compute",
        }
    }
}

impl fmt::Display for Execution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Execution {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Execution::Auto),
            "fragment" => Ok(Execution::Fragment),
            "compute" => Ok(Execution::Compute),
            other => Err(format!(
                "unknown execution `{other}` (expected auto, fragment or compute)"
            )),
        }
    }
}

/// The execution every [`Engine`](super::Engine) made afterwards in this process
/// starts with (a command line sets it once, before any engine exists).
static DEFAULT: AtomicU8 = AtomicU8::new(0);

/// Sets the execution new engines start with (`Engine::set_execution` changes one
/// engine's).
pub fn set_default_execution(e: Execution) {
    let v = match e {
        Execution::Auto => 0,
        Execution::Fragment => 1,
        Execution::Compute => 2,
    };
    DEFAULT.store(v, Ordering::Relaxed);
}

/// The execution new engines start with.
pub fn default_execution() -> Execution {
    match DEFAULT.load(Ordering::Relaxed) {
        1 => Execution::Fragment,
        2 => Execution::Compute,
        _ => Execution::Auto,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(device_type: wgpu::DeviceType, backend: wgpu::Backend) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: "test".into(),
            vendor: 0,
            device: 0,
            device_type,
            device_pci_bus_id: String::new(),
            driver: String::new(),
            driver_info: String::new(),
            backend,
            subgroup_min_size: 4,
            subgroup_max_size: 128,
            transient_saves_memory: None,
            limit_bucket: None,
        }
    }

    #[test]
    fn auto_rule() {
        use wgpu::{Backend as B, DeviceType as D};
        assert_eq!(
            Execution::Auto.resolve(&info(D::Cpu, B::Vulkan)),
            Execution::Fragment
        );
        assert_eq!(
            Execution::Auto.resolve(&info(D::DiscreteGpu, B::Gl)),
            Execution::Fragment
        );
        assert_eq!(
            Execution::Auto.resolve(&info(D::DiscreteGpu, B::Vulkan)),
            Execution::Compute
        );
        assert_eq!(
            Execution::Auto.resolve(&info(D::IntegratedGpu, B::Metal)),
            Execution::Compute
        );
        assert_eq!(
            Execution::Fragment.resolve(&info(D::DiscreteGpu, B::Vulkan)),
            Execution::Fragment
        );
        assert_eq!("Compute".parse::<Execution>(), Ok(Execution::Compute));
        assert!("gpu".parse::<Execution>().is_err());
    }
}
