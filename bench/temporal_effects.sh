#!/usr/bin/env bash
# GPU time of taa and motion_blur against fxaa at 1920x1080: a synthetic sequence
# (a jittered, panning checkerboard with a disc moving the other way, its motion
# vectors and depth as AUX.motion / AUX.depth), the three effects run frame by
# frame in turn in one process, each frame's passes timed with timestamp queries;
# medians over the measured frames, per effect and per pass (benches/temporal_effects.rs).
#
#   bash bench/temporal_effects.sh [FRAMES]      (default 8 measured frames, after 2 warm-up)
#
# Environment (optional): FX_BENCH_SIZE=WxH (default 1920x1080).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
export FX_BENCH_FRAMES=${1:-8}
echo "machine: $(nproc) cores"
cargo bench --quiet --bench temporal_effects
