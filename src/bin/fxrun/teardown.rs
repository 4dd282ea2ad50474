//! The end of a one-off job: its device is not destroyed. Once the job has
//! ended (its outputs written and renamed into place, the pipeline cache saved,
//! the report printed) the process exits and the system frees the device with
//! it. Destroying it first would wait for the device, free each object and close
//! the device and the instance: measured on lavapipe, ~20 ms between the last
//! output and the exit (the device's threads joined, its memory unmapped); on
//! NVIDIA's driver the same work, with its threads, is expected to cost at least
//! as much (not measured). `--watch` and the viewer, which go on, drop theirs.

use fxgraph::gpu::executor::Engine;

/// Leave `kept`, the job's device, to the process's exit.
pub(crate) fn skip_teardown(kept: Option<Engine>) {
    std::mem::forget(kept);
}
