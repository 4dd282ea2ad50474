//! `bench/gpu.sh --quick` runs on this machine's adapter with tiny sizes, so the
//! GPU benchmark cannot rot: it must finish and print its table with a row per
//! measurement and a figure in each (the figures themselves are not checked:
//! performance lives in the benchmark, not in tests).

use fxgraph::gpu::context::{require_gpu, AdapterChoice, GpuContext};
use std::process::Command;

#[test]
fn quick_gpu_benchmark_prints_its_table() {
    if let Err(e) = GpuContext::new(&AdapterChoice::Auto) {
        assert!(!require_gpu(), "FX_REQUIRE_GPU=1 but no adapter: {e}");
        return;
    }
    let work = tempfile::tempdir().unwrap();
    let o = Command::new("bash")
        .args(["bench/gpu.sh", "--quick"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("FXRUN", env!("CARGO_BIN_EXE_fxrun"))
        .env("BENCH_DIR", work.path())
        .output()
        .expect("run bash");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{out}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table: Vec<&str> = out.lines().filter(|l| l.starts_with("| ")).collect();
    // The renderer's rows: the room and the Cornell box under both G-buffer
    // layouts, with figures.
    for scene in ["builtin:room", "Cornell box, 64 lights"] {
        for layout in ["fat", "visibility"] {
            let start = format!("| {scene} | {layout} | 96x54 |");
            let line = table
                .iter()
                .find(|l| l.starts_with(&start))
                .unwrap_or_else(|| panic!("no renderer row `{start}` in\n{out}"));
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            assert!(cells[4].parse::<f64>().is_ok(), "render CPU ms: {line}");
            assert!(cells[7].parse::<f64>().is_ok(), "geometry stage ms: {line}");
        }
    }
    let row = |what: &str| {
        table
            .iter()
            .find(|l| l.starts_with(&format!("| {what}")))
            .unwrap_or_else(|| panic!("no `{what}` row in\n{out}"))
            .split('|')
            .map(str::trim)
            .collect::<Vec<_>>()
    };
    assert!(row("device")[2].contains('('), "{out}");
    let python = Command::new("python3").arg("-V").output().is_ok();
    for what in [
        "glow GPU ms/frame",
        "deinterlace GPU ms/frame",
        "ssao GPU ms/frame",
        "glow y4m→y4m fps",
        "tonemap PNG→PNG, whole process ms",
        "gaussian_blur σ8 PNG→PNG, whole process ms",
    ] {
        let r = row(what);
        for (col, cell) in [("fragment", r[3]), ("compute", r[4])] {
            let number = cell.parse::<f64>();
            assert!(
                number.is_ok() || (!python && cell == "?"),
                "`{what}` {col}: `{cell}` is not a figure\n{out}"
            );
        }
        if python {
            assert!(
                r[5].parse::<f64>().is_ok(),
                "`{what}` ratio `{}`\n{out}",
                r[5]
            );
        }
    }
}
