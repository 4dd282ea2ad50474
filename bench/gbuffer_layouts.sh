#!/usr/bin/env bash
# The two G-buffer layouts of deferred shading (`--gbuffer-layout fat|visibility`,
# issue 26 point 3, docs/renderer.md) on the machine it runs on: the built-in
# room under the orbit camera, RUNS runs of each layout alternating, every
# frame timed (`--timings`; each frame's pass times from the renderer's debug
# log). Per run: the median over the frames of the geometry stage (fat:
# `geometry`; visibility: `visibility` + `material resolve` + the `geometry`
# draws it leaves) and of the whole render (every render pass), and the
# process's CPU time; then the median and range of those over the runs, as a
# markdown table on stdout.
#
#   bash bench/gbuffer_layouts.sh
#
# Environment (optional): FXRUN=path (default: cargo build --release),
# FX_BENCH_SIZE=1920x1080, FX_BENCH_FRAMES=8, FX_BENCH_RUNS=3,
# FX_BENCH_SCENE=builtin:room, WGPU_BACKEND=vulkan.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
SIZE=${FX_BENCH_SIZE:-1920x1080}
FRAMES=${FX_BENCH_FRAMES:-8}
RUNS=${FX_BENCH_RUNS:-3}
SCENE=${FX_BENCH_SCENE:-builtin:room}
command -v python3 >/dev/null || { echo "install python3"; exit 1; }
if [ -z "${FXRUN:-}" ]; then
    cargo build --release --quiet --bin fxrun
    FXRUN="$PWD/target/release/fxrun"
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/fxgraph-gbuffer-layouts.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

echo "machine: $(nproc) cores, $(load); adapter: $("$FXRUN" --adapters 2>/dev/null | head -1)"
echo "$SCENE at $SIZE, $FRAMES frames, orbit camera, tonemap, y4m to disk; $RUNS runs of each layout, alternating"
echo
for run in $(seq 1 "$RUNS"); do
    for layout in fat visibility; do
        /usr/bin/time -f "%U %S" -o "$WORK/$layout-$run.time" \
            env RUST_LOG=fxgraph::render=debug "$FXRUN" tonemap --scene "$SCENE" \
            --gbuffer-layout "$layout" --camera orbit:period=8,elevation=20 --size "$SIZE" \
            --frames "0..$((FRAMES - 1))" -o "$WORK/out.y4m" --timings \
            --timings-json "$WORK/$layout-$run.json" >/dev/null 2>"$WORK/$layout-$run.log"
    done
done
python3 - "$WORK" "$RUNS" <<'PY'
import json, re, statistics, sys
work, runs = sys.argv[1], int(sys.argv[2])
STAGE = {"geometry", "visibility", "material resolve"}
def med_range(v):
    return f"{statistics.median(v):.1f} ({min(v):.1f}–{max(v):.1f})"
print("| layout | geometry stage GPU ms/frame | whole render GPU ms/frame | process CPU s | passes of the stage (median frame of the last run) |")
print("|---|---|---|---|---|")
for layout in ("fat", "visibility"):
    stage, whole, cpu, last = [], [], [], ""
    for run in range(1, runs + 1):
        frames = []
        for line in open(f"{work}/{layout}-{run}.log"):
            m = re.search(r"frame GPU passes: (.*)$", line)
            if m:
                frames.append(dict((k, float(v)) for k, v in
                                   (p.split("=") for p in m.group(1).split("; "))))
        s = [sum(v for k, v in f.items() if k in STAGE) for f in frames]
        stage.append(statistics.median(s))
        whole.append(statistics.median(sum(f.values()) for f in frames))
        u, sy = open(f"{work}/{layout}-{run}.time").read().split()[-2:]
        cpu.append(float(u) + float(sy))
        mid = sorted(frames, key=lambda f: sum(v for k, v in f.items() if k in STAGE))[len(frames) // 2]
        last = ", ".join(f"{k} {v:.1f}" for k, v in mid.items() if k in STAGE)
        json.load(open(f"{work}/{layout}-{run}.json"))
    print(f"| {layout} | {med_range(stage)} | {med_range(whole)} | {med_range(cpu)} | {last} |")
PY
echo
echo "after: $(load)"
