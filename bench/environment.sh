#!/usr/bin/env bash
# Image-based lighting cost: prefiltering time per corpus map (1024x512) and the
# per-frame GPU time of the environment term at 1920x1080 (builtin:room and
# FlightHelmet, deferred and forward, with and without builtin:studio, frames
# interleaved). Runs the ignored test `environment_benchmark` in release mode;
# the Markdown tables go to stdout and target/environment-bench.md.
#
# Environment (optional): FX_BENCH_FRAMES=5, WGPU_BACKEND=vulkan.
# Needs the corpus (../shared/corpus/hdri and ../shared/corpus/gltf/FlightHelmet).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
echo "machine: $(nproc) cores, $(load), $(date '+%Y-%m-%d %H:%M')" >&2
report_test environment-bench.md environment_bench environment_benchmark
