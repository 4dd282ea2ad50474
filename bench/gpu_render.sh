#!/usr/bin/env bash
# The renderer rows of bench/gpu.sh (issue 26), callable by itself: for the
# built-in room with the default chain and the corpus Cornell box with 16,384
# random lights, rendered as sequences under an orbit camera to y4m:
#   - each render pass's GPU time (timestamp queries, last frame of a timed run);
#   - the render CPU time per frame (`scene.render_cpu_ms` of --timings-json over
#     the frames: posing, light culling, uploads and command recording), and the
#     one-time creation of the render pipelines on their first use
#     (`scene.render_pipelines_ms`, once per run);
#   - the geometry stage's GPU time (last frame) under each G-buffer layout
#     (`--gbuffer-layout`, issue 26 point 3): `fat` is the `geometry` pass;
#     `visibility` is the raster pass (`visibility`), the compute material
#     resolve (`material resolve`) and the G-buffer draws it leaves
#     (`geometry`, none for these scenes); docs/renderer.md has the rule that
#     decides between them;
#   - the rendered sequence's frames per second to a y4m file, steady state:
#     two untimed runs of N and 3N frames, fps = 2N / (t(3N) - t(N)), so the
#     process start, the device and the pipelines (once per run) cancel out;
#     and the whole process of the N-frame run (start-up included).
# Every figure comes from this run, on the machine it runs on; markdown rows on
# stdout.
#
#   bash bench/gpu_render.sh [--quick]
#
# --quick: 160x90 and 320x180, 4 frames, 1,024 lights (lavapipe: seconds).
# Environment (optional): FXRUN=path (default: cargo build --release),
# FX_BENCH_SIZES="1920x1080 3840x2160", FX_BENCH_FRAMES=16, FX_BENCH_LIGHTS=16384,
# FX_BENCH_CHAIN="ssao tonemap fxaa" (the effects after the renderer; default:
# tonemap), FX_BENCH_LAYOUTS="fat visibility" (the G-buffer layouts, each a
# row), FX_BENCH_CORNELL=path (the corpus CornellBox.glb, where ../shared is
# not beside the checkout), WGPU_BACKEND=vulkan (recommended on GPU servers).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
QUICK=0
[ "${1:-}" = "--quick" ] && QUICK=1
if [ $QUICK = 1 ]; then
    SIZES=${FX_BENCH_SIZES:-160x90 320x180}
    FRAMES=${FX_BENCH_FRAMES:-4}
    LIGHTS=${FX_BENCH_LIGHTS:-1024}
else
    SIZES=${FX_BENCH_SIZES:-1920x1080 3840x2160}
    FRAMES=${FX_BENCH_FRAMES:-16}
    LIGHTS=${FX_BENCH_LIGHTS:-16384}
fi
CHAIN=${FX_BENCH_CHAIN:-tonemap}
LAYOUTS=${FX_BENCH_LAYOUTS:-fat visibility}
CORNELL=${FX_BENCH_CORNELL:-../shared/corpus/gltf/CornellBox.glb}
need_files "$CORNELL"
command -v python3 >/dev/null || { echo "install python3"; exit 1; }
if [ -z "${FXRUN:-}" ]; then
    cargo build --release --quiet --bin fxrun
    FXRUN="$PWD/target/release/fxrun"
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/fxgraph-gpu-render.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

echo "machine: $(nproc) cores, $(load); adapter: $("$FXRUN" --adapters 2>/dev/null | head -1)"
echo "sequences of $FRAMES frames, orbit camera, effects: $CHAIN, y4m to disk"
echo

# run NAME SIZE ARGS...: one timed run (--timings-json) and one untimed run.
# Prints "cpu_ms_per_frame fps passes" (passes: name=ms;...).
run() {
    local name=$1 size=$2
    shift 2
    local json="$WORK/$name-$size.json"
    # shellcheck disable=SC2086
    "$FXRUN" $CHAIN --scene "$@" --camera orbit:period=8,elevation=20 --size "$size" \
        --frames "0..$((FRAMES - 1))" -o "$WORK/timed.y4m" --timings --timings-json "$json" \
        >/dev/null 2>&1
    local t=()
    for n in "$FRAMES" $((3 * FRAMES)); do
        local t0 t1
        t0=$(date +%s%N)
        # shellcheck disable=SC2086
        "$FXRUN" $CHAIN --scene "$@" --camera orbit:period=8,elevation=20 --size "$size" \
            --frames "0..$((n - 1))" -o "$WORK/untimed.y4m" 2>/dev/null
        t1=$(date +%s%N)
        t+=($((t1 - t0)))
    done
    python3 - "$json" "$FRAMES" "${t[0]}" "${t[1]}" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
frames = int(sys.argv[2])
s = r["scene"]
cpu = s["render_cpu_ms"] / max(r["frames_in"], 1)
once = s.get("render_pipelines_ms", 0.0)
short, long = int(sys.argv[3]) / 1e9, int(sys.argv[4]) / 1e9
# the 3N-frame run no longer than the N-frame one (a loaded machine, few
# frames): no steady-state figure, shown as "-"
steady = f"{2 * frames / (long - short):.1f}" if long > short else "-"
whole = frames / short
passes = ";".join(f"{n}={ms:.3f}" for n, ms in s["render_passes"])
print(f"{cpu:.2f} {once:.1f} {steady}/{whole:.1f} {passes}")
EOF
}

echo "| scene | G-buffer layout | size | render CPU ms/frame | pipelines created (ms, once) | sequence fps to y4m: steady / whole process of $FRAMES frames | geometry stage GPU ms (last frame) | render GPU ms per pass (last frame) |"
echo "|---|---|---|---|---|---|---|---|"
for size in $SIZES; do
    for scene in room cornell; do
        for layout in $LAYOUTS; do
            case $scene in
                room) label="builtin:room"; args=(builtin:room) ;;
                cornell) label="Cornell box, $LIGHTS lights"; args=("$CORNELL" --lights "$LIGHTS") ;;
            esac
            read -r cpu once fps passes < <(run "$scene-$layout" "$size" "${args[@]}" --gbuffer-layout "$layout")
            total=$(echo "$passes" | tr ';' '\n' | awk -F= '{s += $2} END {printf "%.2f", s}')
            geometry=$(echo "$passes" | tr ';' '\n' | awk -F= '$1 == "geometry" || $1 == "visibility" || $1 == "material resolve" {s += $2} END {printf "%.3f", s}')
            echo "| $label | $layout | $size | $cpu | $once | $fps | $geometry | ${passes//;/, } (sum $total) |"
        done
    done
done
echo
echo "after: $(load)"
