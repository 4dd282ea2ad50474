//! What the GPU benchmarks share: the adapter (none: the benchmark is skipped),
//! the environment variables they read, medians.

use fxgraph::gpu::context::{AdapterChoice, GpuContext};

/// The adapter, or `None` when the harness only lists benchmarks (`--list`) or
/// there is no adapter (`what` is then reported skipped).
pub fn adapter(what: &str) -> Option<GpuContext> {
    if std::env::args().any(|a| a == "--list") {
        return None;
    }
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    match GpuContext::new(&AdapterChoice::Auto) {
        Ok(ctx) => Some(ctx),
        Err(_) => {
            eprintln!("no adapter: {what} benchmark skipped");
            None
        }
    }
}

/// FX_BENCH_SIZE=WxH, else `default`.
pub fn size(default: (u32, u32)) -> (u32, u32) {
    std::env::var("FX_BENCH_SIZE")
        .ok()
        .and_then(|s| {
            let (a, b) = s.split_once('x')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .unwrap_or(default)
}

/// The environment variable `name` parsed, else `default`.
pub fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// The median (the upper one of an even count); `v` must not be empty.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
