#!/usr/bin/env bash
# A rendered sequence's GPU time per frame against a still's (target <= 1.15x) and
# the motion vectors' cost against the G-buffer pass (target <= 10 %), at 1280x720
# on an animated skinned corpus model (RiggedSimple by default): still and sequence
# frames rendered in alternating blocks in one process, every pass timed with
# timestamp queries; medians per mode and per pass (benches/scene_sequence.rs).
#
#   bash bench/scene_sequence.sh [FRAMES]      (default 16 frames per block, 2 rounds)
#
# Environment (optional): FX_BENCH_SIZE=WxH (1280x720), FX_BENCH_SCENE=FILE,
# FX_BENCH_ROUNDS=2, FX_BENCH_TECHNIQUE=deferred|light-prepass|forward.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
export FX_BENCH_FRAMES=${1:-16}
echo "machine: $(nproc) cores, $(load)"
cargo bench --quiet --bench scene_sequence
echo "after: $(load)"
