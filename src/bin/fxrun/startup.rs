//! The process's own clock, for the `process` row of `--timings` and
//! `--timings-json`: when `main` began, how long the process ran before it (exec,
//! dynamic loading), and when the job began, so that the split covers the whole
//! process and not only the job's internal total.
//!
//! Before `main`: the kernel's start time of the process (`/proc/self/stat`, in
//! clock ticks of 10 ms: fork, not exec) against `CLOCK_BOOTTIME`, the clock it
//! counts in. The tick makes it ±5 ms (the middle of the tick is taken); `None`
//! where there is no `/proc` (not Linux).

use std::sync::OnceLock;
use std::time::Instant;

/// Where the process's time went, in milliseconds: `process_ms` = `before_main_ms`
/// + `since_main_ms`, and `since_main_ms` = `setup_ms` + `job_ms` + `rest_ms`.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub(crate) struct ProcessTimes {
    /// From the process's start (its fork) to `main`'s first line: exec, dynamic
    /// loading (±5 ms; `None` without `/proc`).
    pub before_main_ms: Option<f64>,
    /// From `main`'s first line to the job's start: arguments, logging.
    pub setup_ms: f64,
    /// The job's internal total (`wall_ms`).
    pub job_ms: f64,
    /// The rest up to the report: what the job did outside its total, printing.
    pub rest_ms: f64,
    pub since_main_ms: f64,
    /// From the process's start to the report.
    pub process_ms: f64,
}

/// When `main` began, and the estimate of the time before it.
struct MainStart {
    at: Instant,
    before_main_ms: Option<f64>,
}

static MAIN: OnceLock<MainStart> = OnceLock::new();
static JOB: OnceLock<Instant> = OnceLock::new();

/// The first thing `main` does: the time now, and the time the process ran before.
pub(crate) fn mark_main() {
    let at = Instant::now();
    let before_main_ms = before_main_ms();
    let _ = MAIN.set(MainStart { at, before_main_ms });
}

/// The arguments are parsed and the logger set up: the job begins.
pub(crate) fn mark_job() {
    let _ = JOB.set(Instant::now());
}

/// Where the process's time went up to now, with `job_total_ms` the job's own
/// internal total (`RunReport::wall_ms`).
pub(crate) fn times(job_total_ms: f64) -> Option<ProcessTimes> {
    let main = MAIN.get()?;
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let since_main_ms = ms(main.at.elapsed());
    let setup_ms = JOB.get().map_or(0.0, |j| ms(j.duration_since(main.at)));
    let rest_ms = (since_main_ms - setup_ms - job_total_ms).max(0.0);
    Some(ProcessTimes {
        before_main_ms: main.before_main_ms,
        setup_ms,
        job_ms: job_total_ms,
        rest_ms,
        since_main_ms,
        process_ms: since_main_ms + main.before_main_ms.unwrap_or(0.0),
    })
}

/// The `--timings` line of `times`.
pub(crate) fn line(t: &ProcessTimes) -> String {
    let before = t
        .before_main_ms
        .map_or_else(|| "-".to_string(), |b| format!("{b:.1} (±5)"));
    format!(
        "process {:.1} ms from its start to this line: before main {before} | setup {:.1} (arguments, logging) | job {:.1} (the job's total) | rest {:.1} (outside the job's total)",
        t.process_ms, t.setup_ms, t.job_ms, t.rest_ms
    )
}

/// Milliseconds between the process's start (its fork) and now, read first thing
/// in `main`.
#[cfg(target_os = "linux")]
fn before_main_ms() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces and parentheses):
    // `state` is field 3, `starttime` field 22.
    let after = &stat[stat.rfind(')')? + 1..];
    let ticks: u64 = after.split_whitespace().nth(19)?.parse().ok()?;
    // SAFETY: `sysconf` reads a constant of the system; no memory is passed.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if hz <= 0 {
        return None;
    }
    let mut now = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `now` is a valid, writable timespec for the call's duration.
    if unsafe { libc::clock_gettime(libc::CLOCK_BOOTTIME, &mut now) } != 0 {
        return None;
    }
    let now_ms = now.tv_sec as f64 * 1e3 + now.tv_nsec as f64 / 1e6;
    let tick_ms = 1e3 / hz as f64;
    // The start lies within its tick: take the tick's middle.
    let start_ms = ticks as f64 * tick_ms + tick_ms / 2.0;
    Some((now_ms - start_ms).max(0.0))
}

#[cfg(not(target_os = "linux"))]
fn before_main_ms() -> Option<f64> {
    None
}
