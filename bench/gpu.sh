#!/usr/bin/env bash
# One GPU benchmark, one command: fxrun on whatever adapter it picks, in both
# execution paths, printing one Markdown table at the end.
#
#   bash bench/gpu.sh            full run: 1920x1080 and 3840x2160, 20 timed frames
#   bash bench/gpu.sh --quick    tiny sizes, one effect of each kind (lavapipe,
#                                tests/bench_gpu.rs runs it so it cannot rot)
#
# Settings (environment): FXRUN, FXRUN_ARGS (e.g. "--adapter 1"), SIZES, FRAMES,
# VIDEO_FRAMES, STILL / TEMPORAL / SCENE / VIDEO_EFFECTS (effect lists), RUNS,
# BENCH_DIR (work folder, default /tmp/fxgraph-gpu-bench), RUN_LIMIT (seconds one
# fxrun process may take before it counts as failed, default 120),
# FX_BENCH_CORNELL (see bench/gpu_render.sh).
#
# Needs only the fxrun binary (FXRUN=path, default target/release/fxrun, built
# here when cargo exists) and bash; python3 formats the table, and when it can
# import cv2 / torch the whole-process peers are timed too. No network. On a GPU
# server with only the driver, see ../shared/perf/README.md (libvulkan1, the
# stripped binary).
#
# Rows:
# - device: the adapter and backend fxrun picked;
# - effect rows: GPU time per frame of every built-in effect (the sum of its
#   passes' timestamp medians over FRAMES frames), fragment and compute, and the
#   ratio compute / fragment (below 1: compute is faster). Input: the built-in
#   room rendered once to y4m; effects reading AUX.* run on the rendered room;
#   their per-pass detail goes to $OUT/passes.md;
# - video rows: whole-pipeline fps, y4m in and out (stdout), for
#   temporal_denoise, deinterlace and glow; and with compute execution, the
#   Y'CbCr conversion on the CPU (--ycbcr cpu) against the GPU (--ycbcr gpu);
# - process rows: a 1080p PNG through tonemap, and gaussian_blur sigma 8, whole
#   process wall time (median of 5), with OpenCV and PyTorch doing the same blur
#   (PNG in and out) where python3 has them;
# - the renderer's rows (bench/gpu_render.sh): each render pass's GPU time, the
#   render CPU per frame and rendered-sequence fps to y4m, the room and the
#   Cornell box with 16,384 lights, each under both G-buffer layouts (the fat
#   G-buffer and the visibility buffer: its geometry stage's GPU time against
#   the fat `geometry` pass decides issue 26 point 3, docs/renderer.md).
set -euo pipefail
. "$(dirname "$0")/lib.sh"

QUICK=0
[ "${1:-}" = "--quick" ] && QUICK=1
OUT=${BENCH_DIR:-/tmp/fxgraph-gpu-bench}
mkdir -p "$OUT"
if [ -z "${FXRUN:-}" ]; then
    FXRUN=target/release/fxrun
    if command -v cargo >/dev/null && [ "$QUICK" = 0 ]; then
        cargo build --release --quiet --bin fxrun
    fi
fi
[ -x "$FXRUN" ] || { echo "no fxrun binary at $FXRUN (set FXRUN=...)"; exit 1; }
# Every fxrun process runs under a time limit, so that one hang costs one row,
# not the whole benchmark.
FX="timeout ${RUN_LIMIT:-120} $FXRUN ${FXRUN_ARGS:-}"
PY=$(command -v python3 || true)

if [ "$QUICK" = 1 ]; then
    SIZES=${SIZES:-96x54}
    FRAMES=${FRAMES:-3}
    VIDEO_FRAMES=${VIDEO_FRAMES:-4}
    STILL=${STILL:-"glow"}
    TEMPORAL=${TEMPORAL:-"deinterlace"}
    SCENE=${SCENE:-"ssao"}
    VIDEO_EFFECTS=${VIDEO_EFFECTS:-"glow"}
    PNG_SIZE=${PNG_SIZE:-96x54}
    RUNS=${RUNS:-1}
else
    SIZES=${SIZES:-"1920x1080 3840x2160"}
    FRAMES=${FRAMES:-20}
    VIDEO_FRAMES=${VIDEO_FRAMES:-120}
    STILL=${STILL:-"bloom chroma_key color_grade edges format_convert fxaa gaussian_blur glow pencil sharpen tonemap vignette"}
    TEMPORAL=${TEMPORAL:-"auto_exposure chroma_key_temporal deinterlace frame_blend motion_trail temporal_denoise"}
    SCENE=${SCENE:-"dof fog motion_blur outline ssao ssgi taa"}
    VIDEO_EFFECTS=${VIDEO_EFFECTS:-"temporal_denoise deinterlace glow"}
    PNG_SIZE=${PNG_SIZE:-1920x1080}
    RUNS=${RUNS:-5}
fi
ROWS="$OUT/rows.tsv"
: > "$ROWS"
: > "$OUT/passes.md"
row() { printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$@" >> "$ROWS"; }

# gpu_ms JSON: the effect's GPU ms per frame (sum of the passes' medians) and the
# per-pass detail appended to passes.md.
gpu_ms() {
    [ -n "$PY" ] || { echo "?"; return; }
    "$PY" - "$1" "$2" >> "$OUT/passes.md" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
passes = r.get("passes", [])
total = sum(p["gpu_ms"] for p in passes if p.get("gpu_ms") is not None)
timed = any(p.get("gpu_ms") is not None for p in passes)
print(f"| {sys.argv[2]} | " + ("%.3f" % total if timed else "no timestamps") + " | " +
      "; ".join(f"{p['path']} {p['execution']} {p['gpu_ms'] if p['gpu_ms'] is None else round(p['gpu_ms'], 3)}" for p in passes) + " |")
with open(sys.argv[1] + ".total", "w") as f:
    f.write("%.3f" % total if timed else "-")
EOF
    cat "$1.total"
}

# chain_ms JSON LABEL: "TOTAL (render R + effects E)" for a scene job: the render
# passes of the last frame and the effect passes' medians, in GPU ms.
chain_ms() {
    [ -n "$PY" ] || { echo "?"; return; }
    "$PY" - "$1" "$2" >> "$OUT/passes.md" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
fx = [p for p in r.get("passes", []) if p.get("gpu_ms") is not None]
rp = r.get("scene", {}).get("render_passes", [])
e = sum(p["gpu_ms"] for p in fx)
g = sum(ms for _, ms in rp)
print(f"| {sys.argv[2]} | {g + e:.3f} | " + "; ".join(f"{n} {ms:.3f}" for n, ms in rp) + "; "
      + "; ".join(f"{p['path']} {p['execution']} {p['gpu_ms']:.3f}" for p in fx) + " |")
with open(sys.argv[1] + ".total", "w") as f:
    f.write(f"{g + e:.3f} (render {g:.2f} + effects {e:.2f})" if fx and rp else "-")
EOF
    cat "$1.total"
}

ratio() { [ -n "$PY" ] && "$PY" -c "import sys; a,b=sys.argv[1:]; print('%.2f' % (float(b)/float(a)) if a not in ('-','?','0.000') and b not in ('-','?') else '-')" "$1" "$2" || echo "-"; }

# median_wall N CMD...: the median wall time of N runs, in ms.
median_wall() {
    local n=$1; shift
    local times=()
    for _ in $(seq "$n"); do
        local t0 t1
        t0=$(date +%s%N)
        "$@" >/dev/null 2>&1
        t1=$(date +%s%N)
        times+=($(( (t1 - t0) / 1000000 )))
    done
    printf '%s\n' "${times[@]}" | sort -n | sed -n "$(( (n + 1) / 2 ))p"
}

# The device.
$FX tonemap --scene builtin:room --size 32x18 -o "$OUT/probe.png" --timings-json "$OUT/probe.json" >/dev/null 2>&1
DEVICE=$([ -n "$PY" ] && "$PY" -c "import json,sys; r=json.load(open(sys.argv[1])); print(r['adapter'] + ' (' + r['backend'] + ')')" "$OUT/probe.json" || $FX --adapters | head -1)
row "device" "$DEVICE" "" "" "" ""

for size in $SIZES; do
    # The input: the built-in room, rendered once per size.
    ROOM="$OUT/room_$size.y4m"
    [ -f "$ROOM" ] || $FX --scene builtin:room --size "$size" --frames "0..$((FRAMES - 1))" --camera orbit -o "$ROOM" >/dev/null 2>&1
    for effect in $STILL $TEMPORAL $SCENE; do
        declare -A ms=()
        for exec in fragment compute; do
            json="$OUT/$effect-$size-$exec.json"
            if [[ " $SCENE " == *" $effect "* ]]; then
                src=(--scene builtin:room --size "$size" --frames "0..$((FRAMES - 1))" --camera orbit)
            else
                src=(-i "$ROOM")
            fi
            if $FX "$effect" "${src[@]}" -o - --execution "$exec" --timings --timings-json "$json" >/dev/null 2>"$OUT/err.txt"; then
                ms[$exec]=$(gpu_ms "$json" "$effect $size $exec")
            else
                ms[$exec]="failed"
                sed 's/^/    /' "$OUT/err.txt" | tail -3
            fi
        done
        row "$effect GPU ms/frame" "$size" "${ms[fragment]}" "${ms[compute]}" "$(ratio "${ms[fragment]}" "${ms[compute]}")" ""
    done
    # The room with its default chain (ssao fog glow tonemap fxaa): the render
    # passes' GPU time (last frame) plus the effect passes' medians, the figure
    # issue 26's targets are set against.
    declare -A chain=()
    for exec in fragment compute; do
        json="$OUT/default-chain-$size-$exec.json"
        if $FX --scene builtin:room --size "$size" --frames "0..$((FRAMES - 1))" --camera orbit -o - \
            --execution "$exec" --timings --timings-json "$json" >/dev/null 2>"$OUT/err.txt"; then
            chain[$exec]=$(chain_ms "$json" "room + default chain $size $exec")
        else
            chain[$exec]="failed"
            sed 's/^/    /' "$OUT/err.txt" | tail -3
        fi
    done
    row "room + default chain, GPU ms/frame (render + effects)" "$size" "${chain[fragment]}" "${chain[compute]}" "$(ratio "${chain[fragment]%% *}" "${chain[compute]%% *}")" ""
done

# Whole-pipeline video: y4m in, y4m out (to a pipe), fps.
VSIZE=${SIZES%% *}
VIDEO="$OUT/video_$VSIZE.y4m"
[ -f "$VIDEO" ] || $FX --scene builtin:room --size "$VSIZE" --frames "0..$((VIDEO_FRAMES - 1))" --camera orbit -o "$VIDEO" >/dev/null 2>&1
for effect in $VIDEO_EFFECTS; do
    declare -A fps=()
    for exec in fragment compute; do
        t=$(median_wall 1 $FX "$effect" -i "$VIDEO" -o - --execution "$exec")
        fps[$exec]=$([ -n "$PY" ] && "$PY" -c "print('%.1f' % ($VIDEO_FRAMES / ($t / 1000)))" || echo "${t}ms")
    done
    row "$effect y4m→y4m fps ($VIDEO_FRAMES frames)" "$VSIZE" "${fps[fragment]}" "${fps[compute]}" "$(ratio "${fps[compute]}" "${fps[fragment]}")" ""
    # Where Y'CbCr is converted (compute execution): the CPU (io/yuv) or the GPU (gpu/yuv).
    declare -A yfps=()
    for side in cpu gpu; do
        t=$(median_wall 1 $FX "$effect" -i "$VIDEO" -o - --execution compute --ycbcr "$side")
        yfps[$side]=$([ -n "$PY" ] && "$PY" -c "print('%.1f' % ($VIDEO_FRAMES / ($t / 1000)))" || echo "${t}ms")
    done
    row "$effect y4m→y4m fps, compute, --ycbcr cpu | gpu" "$VSIZE" "${yfps[cpu]}" "${yfps[gpu]}" "$(ratio "${yfps[cpu]}" "${yfps[gpu]}")" "columns: Y'CbCr converted on the CPU, on the GPU"
done

# Whole process on a PNG.
PNG="$OUT/photo_$PNG_SIZE.png"
[ -f "$PNG" ] || $FX tonemap --scene builtin:room --size "$PNG_SIZE" -o "$PNG" >/dev/null 2>&1
declare -A t=()
for exec in fragment compute; do
    t[$exec]=$(median_wall "$RUNS" $FX tonemap -i "$PNG" -o "$OUT/tm.png" --execution "$exec")
done
row "tonemap PNG→PNG, whole process ms" "$PNG_SIZE" "${t[fragment]}" "${t[compute]}" "$(ratio "${t[fragment]}" "${t[compute]}")" ""
for exec in fragment compute; do
    t[$exec]=$(median_wall "$RUNS" $FX gaussian_blur --set sigma=8 -i "$PNG" -o "$OUT/blur.png" --execution "$exec")
done
peer=""
if [ -n "$PY" ] && "$PY" -c "import cv2" 2>/dev/null; then
    cv=$(median_wall "$RUNS" "$PY" bench/blur_opencv.py "$PNG" "$OUT/blur_cv.png" 8)
    peer="OpenCV ${cv} ms"
fi
if [ -n "$PY" ] && "$PY" -c "import torch, cv2" 2>/dev/null; then
    pt=$(median_wall "$RUNS" "$PY" bench/blur_torch.py "$PNG" "$OUT/blur_torch.png" 8)
    peer="$peer${peer:+; }PyTorch ${pt} ms"
fi
row "gaussian_blur σ8 PNG→PNG, whole process ms" "$PNG_SIZE" "${t[fragment]}" "${t[compute]}" "$(ratio "${t[fragment]}" "${t[compute]}")" "${peer:-no python3 cv2/torch}"

# Where the whole-process time of the PNG run goes: fxrun's own split
# (--timings: decode, device creation, pipelines, upload, passes, readback,
# encode, total; then the process row: from the process's start, before main,
# setup, the job, the rest) of one compute run, and the process's wall time
# (what is left of it past the process row is the exit). Three runs: the
# first may fill the pipeline cache.
SPLIT=""
for i in 1 2 3; do
    t0=$(date +%s%N)
    lines=$($FX tonemap -i "$PNG" -o "$OUT/tm.png" --execution compute --timings 2>&1 | grep -E "^(compile|process) " || true)
    t1=$(date +%s%N)
    SPLIT="$SPLIT
  run $i: $(echo "$lines" | paste -sd '|' - | sed 's/|/ || /'); process wall $(( (t1 - t0) / 1000000 )) ms"
done

# The renderer rows (bench/gpu_render.sh): render passes, render CPU per frame,
# rendered-sequence fps; printed after the table.
if [ "$QUICK" = 1 ]; then
    FXRUN="$FXRUN" FX_BENCH_SIZES=96x54 FX_BENCH_FRAMES=2 FX_BENCH_LIGHTS=64 \
        bash bench/gpu_render.sh --quick > "$OUT/render.md" 2>&1 || echo "bench/gpu_render.sh failed" >> "$OUT/render.md"
else
    FXRUN="$FXRUN" bash bench/gpu_render.sh > "$OUT/render.md" 2>&1 || echo "bench/gpu_render.sh failed" >> "$OUT/render.md"
fi

echo
echo "$(load)"
echo
echo "tonemap PNG→PNG ($PNG_SIZE), compute runs:$SPLIT"
echo
echo "| what | size | fragment | compute | compute / fragment | peer |"
echo "|---|---|---|---|---|---|"
while IFS=$'\t' read -r a b c d e f; do
    echo "| $a | $b | $c | $d | $e | $f |"
done < "$ROWS"
echo
echo "Renderer (bench/gpu_render.sh):"
cat "$OUT/render.md"
echo
echo "(per-pass detail: $OUT/passes.md. The ratio is always compute time / fragment time: below 1, compute is faster; for fps rows it is fragment fps / compute fps)"
