#!/usr/bin/env bash
# Feature-selection benchmark (the materials-and-effects paper: "conditional compilation made rendering
# 1.5-2x faster than shaders with branches"): builtin:bench with the standard
# surface in nine map combinations (bench/materials_maps.fx) under random point
# lights, rendered with preprocessor variants, override constants and run-time
# branching, forward and deferred, at 1920x1080. Runs the ignored test
# `variant_benchmark` in release mode; the Markdown report goes to stdout and
# target/materials-bench.md.
#
# Environment (optional): FX_BENCH_SIZE=1920x1080, FX_BENCH_FRAMES=5,
# FX_BENCH_LIGHTS=16.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
report_test materials-bench.md materials variant_benchmark
