#!/usr/bin/env bash
# Renderer benchmark: frame time of deferred vs light pre-pass vs forward shading
# on builtin:bench (~100K triangles) with 1..1024 random point lights at 1920x1080,
# plus G-buffer bytes per pixel. Runs the ignored test `renderer_benchmark` in
# release mode; the Markdown report goes to stdout and target/renderer-bench.md.
#
# Environment (optional): FX_BENCH_SIZE=1920x1080, FX_BENCH_LIGHTS=1,8,32,128,512,1024,
# FX_BENCH_FRAMES=3, FX_BENCH_WARMUP=1, FX_BENCH_TECHNIQUES=deferred,light-prepass,forward,
# WGPU_BACKEND=vulkan (lavapipe on a machine without a GPU).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
report_test renderer-bench.md deferred renderer_benchmark
