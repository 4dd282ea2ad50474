//! The environment of the benchmarks kept among the tests (ignored tests run
//! with `--ignored`): `FX_BENCH_*` settings and the report they print.
#![allow(dead_code)]

/// The setting `FX_BENCH_<name>` parsed, or `None` when it is not set (a value
/// that does not parse stops the benchmark, naming it).
pub fn setting<T: std::str::FromStr>(name: &str) -> Option<T> {
    let key = format!("FX_BENCH_{name}");
    let value = std::env::var(&key).ok()?;
    Some(
        value
            .parse()
            .unwrap_or_else(|_| panic!("{key}={value} does not parse")),
    )
}

/// `FX_BENCH_SIZE=WxH`, or `None` when it is not set.
pub fn size() -> Option<(u32, u32)> {
    let s: String = setting("SIZE")?;
    let (w, h) = s.split_once('x').expect("FX_BENCH_SIZE=WxH");
    Some((w.parse().unwrap(), h.parse().unwrap()))
}

/// Prints the benchmark's `report` and writes it to `FX_BENCH_OUT` when set.
pub fn publish(report: &impl std::fmt::Display) {
    println!("{report}");
    if let Ok(out) = std::env::var("FX_BENCH_OUT") {
        std::fs::write(&out, report.to_string()).unwrap();
    }
}
