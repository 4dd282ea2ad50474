#!/usr/bin/env bash
# The viewer's cost: frame time of `fxrun glow --view` (the effect recorded with
# Prepared::record into the frame's encoder, the egui panel with the pass list, the
# image pass, present, and the wait for the GPU) against Prepared::record alone
# (examples/record_frames.rs: record, submit, wait), glow on a 1280x720 image,
# interleaved rounds; and a parameter change (set at frame 10 through the panel's
# code path) to the frame that shows it.
#
# bash bench/viewer.sh [FRAMES] [ROUNDS]   (defaults 40 and 5)
# Needs Xvfb (or DISPLAY) and ImageMagick's convert. Release build.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
FRAMES=${1:-40}
ROUNDS=${2:-5}

cargo build --release --quiet --bin fxrun --example record_frames
tmp=$(mktemp -d)
xvfb_pid=""
cleanup() {
    [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
    rm -rf "$tmp"
}
trap cleanup EXIT

if [ -z "${DISPLAY:-}" ]; then
    # A screen large enough for the image at 1:1 and the panel.
    for n in $(seq 150 199); do
        [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ] && continue
        Xvfb ":$n" -screen 0 1920x1200x24 -nolisten tcp >/dev/null 2>&1 &
        xvfb_pid=$!
        export DISPLAY=":$n"
        for _ in $(seq 1 100); do [ -e "/tmp/.X11-unix/X$n" ] && break; sleep 0.1; done
        break
    done
fi

convert examples/data/rocket.jpg -resize '1280x720!' "$tmp/in.png"
echo "machine: $(nproc) cores, $(load); adapter: $(target/release/fxrun --adapters | head -1)"
echo "glow 1280x720, $FRAMES frames per run, medians after 2 warm-up frames"
for r in $(seq 1 "$ROUNDS"); do
    rec=$(target/release/examples/record_frames glow "$tmp/in.png" "$FRAMES" | sed -E 's/.*median frame ([0-9.]+) ms.*/\1/')
    out=$(target/release/fxrun glow -i "$tmp/in.png" --view --view-frames "$FRAMES" \
        --view-do "10:set brightPass.threshold=0.3" --timings 2>&1)
    view=$(echo "$out" | sed -nE 's/.*median frame ([0-9.]+) ms.*/\1/p')
    change=$(echo "$out" | sed -nE 's/.*parameter change shown in frame ([0-9]+), ([0-9.]+) ms.*/frame \1 (set after frame 10), \2 ms/p')
    ratio=$(awk -v v="$view" -v r="$rec" 'BEGIN { printf "%.3f", v / r }')
    echo "round $r: record alone $rec ms, viewer $view ms (x$ratio); parameter change shown in $change"
    ratios="${ratios:-} $ratio"
done
echo "median viewer / record alone over the rounds: x$(echo $ratios | tr ' ' '\n' | sort -n | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')"
