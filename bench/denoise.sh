#!/usr/bin/env bash
# Temporal denoising: fxrun temporal_denoise (defaults) against ffmpeg hqdn3d (at
# its defaults and tuned) and nlmeans (tuned) on a noisy camera pan cut from a real
# photo, with the clean frames as the truth, in one run.
#
#   bash bench/denoise.sh [FRAMES] [RUNS]   (default 40 frames, 3 timing runs)
#
# Sequence (bench/denoise_seq.py): ../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg,
# a 640x360 window panning by about (1.3, 0.55) px per frame with a slow wobble
# (sub-pixel positions throughout), Gaussian noise of standard deviation 10 (8-bit
# code values, per channel, seed 12345): about 28.4 dB. Quality: PSNR in dB (8-bit
# RGB, mean over frames 6..FRAMES: the first 5 frames are left out for every
# method alike, the warm-up of the recursive filters) and a ghosting figure, the
# 99.9th percentile of max over r, g, b |out - clean| (8-bit, mean over the same
# frames): trails and misregistered edges raise it before they move the PSNR.
# "tuned" = the best PSNR of a small sweep, all sweep rows printed. ffmpeg runs its
# filters in yuv444p (no chroma subsampling) with 2 threads; every tool writes PNG.
# A row for the same photo with a still camera (no pan) shows what the motion
# compensation costs. Speed: 1920x1080, 10 frames of the same pan, median wall time of RUNS runs
# (PNG in -> PNG out, whole process), in ms per frame.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
N=${1:-40}
RUNS=${2:-3}
WORK=${BENCH_DIR:-/tmp/fxgraph-denoise}
PHOTO=../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
SKIP=5
need_files "$PHOTO"
need_ffmpeg_cv
cargo build --release --quiet --bin fxrun
FX="$PWD/target/release/fxrun"
SEQ="python3 $PWD/bench/denoise_seq.py"
echo "fxrun adapter: $($FX --adapters | head -1)"
echo "machine: $(nproc) cores; ffmpeg $(ffmpeg -version | head -1 | cut -d' ' -f3)"
mkdir -p "$WORK"
Q="$WORK/q_640x360_$N"
HD="$WORK/hd_1920x1080_10"
[ -f "$Q/noisy/$(printf %04d "$N").png" ] || { rm -rf "$Q"; $SEQ make "$PHOTO" "$Q" 640 360 "$N" 10; }
ST="$WORK/still_640x360_$N"
[ -f "$ST/noisy/$(printf %04d "$N").png" ] || { rm -rf "$ST"; $SEQ make "$PHOTO" "$ST" 640 360 "$N" 10 0; }
[ -f "$HD/noisy/0010.png" ] || { rm -rf "$HD"; $SEQ make "$PHOTO" "$HD" 1920 1080 10 10; }

now() { date +%s.%N; }
# quality LABEL DIR COMMAND...: runs COMMAND (which writes DIR/%04d.png), prints a row.
quality() {
    local label=$1 dir=$2; shift 2
    rm -rf "$dir"; mkdir -p "$dir"
    local t0 t1
    t0=$(now)
    "$@" >/dev/null 2>"$WORK/err.txt" || { echo "$label FAILED"; cat "$WORK/err.txt"; return; }
    t1=$(now)
    printf '%-40s %8s dB  ghost %6s  %7.0f ms\n' "$label" \
        "$($SEQ psnr "$Q/clean" "$dir" $SKIP)" "$($SEQ ghost "$Q/clean" "$dir" $SKIP)" \
        "$(echo "($t1 - $t0) * 1000" | bc)" | tee -a "$WORK/quality.txt"
}
ff() { # IN_DIR OUT_DIR FILTER
    ffmpeg -v error -y -threads 2 -filter_threads 2 -i "$1/%04d.png" \
        -vf "format=yuv444p,$3,format=rgb24" -compression_level 1 "$2/%04d.png"
}
: > "$WORK/quality.txt"
echo
echo "== quality: 640x360, $N frames, noise sigma 10/255; PSNR of frames $((SKIP + 1))..$N, wall time of the whole run"
printf '%-40s %8s dB  ghost %6s\n' "noisy input" "$($SEQ psnr "$Q/clean" "$Q/noisy" $SKIP)" "$($SEQ ghost "$Q/clean" "$Q/noisy" $SKIP)"
quality "fxrun temporal_denoise (defaults)" "$WORK/o_fx" "$FX" temporal_denoise -i "$Q/noisy/%04d.png" -o "$WORK/o_fx/%04d.png"
quality "ffmpeg hqdn3d (defaults)" "$WORK/o_hq" ff "$Q/noisy" "$WORK/o_hq" hqdn3d
HQ_SWEEP="6:4.5:12:12 8:6:15:15 8:6:20:20 10:7.5:20:20 10:7.5:25:25 12:9:25:25"
for p in $HQ_SWEEP; do
    quality "  sweep hqdn3d=$p" "$WORK/o_hq_$p" ff "$Q/noisy" "$WORK/o_hq_$p" "hqdn3d=$p"
done
NL_SWEEP="s=2:p=5:r=15 s=2.5:p=5:r=15 s=3:p=5:r=15 s=3.5:p=5:r=15 s=4:p=7:r=15"
for p in $NL_SWEEP; do
    quality "  sweep nlmeans=$p" "$WORK/o_nl_$p" ff "$Q/noisy" "$WORK/o_nl_$p" "nlmeans=$p"
done
best() { grep "sweep $1=" "$WORK/quality.txt" | awk '{print $3 "\t" $0}' | sort -g | tail -1 | cut -f2-; }
HQ_BEST=$(best hqdn3d | awk '{print $2}' | cut -d= -f2)
NL_BEST=$(best nlmeans | awk '{print $2}' | cut -d= -f2-)
# The same photo with a still camera: what the motion compensation costs on the pan.
rm -rf "$WORK/o_still"; mkdir -p "$WORK/o_still"
"$FX" temporal_denoise -i "$ST/noisy/%04d.png" -o "$WORK/o_still/%04d.png" >/dev/null 2>"$WORK/err.txt" || cat "$WORK/err.txt"
printf '%-40s %8s dB  ghost %6s  (still camera; noisy %s dB)\n' "  fxrun temporal_denoise, no pan" \
    "$($SEQ psnr "$ST/clean" "$WORK/o_still" $SKIP)" "$($SEQ ghost "$ST/clean" "$WORK/o_still" $SKIP)" \
    "$($SEQ psnr "$ST/clean" "$ST/noisy" $SKIP)"
echo "-- best of the sweeps:"
echo "ffmpeg hqdn3d tuned:  $(best hqdn3d | sed 's/^ *sweep //')"
echo "ffmpeg nlmeans tuned: $(best nlmeans | sed 's/^ *sweep //')"

echo
echo "== speed: 1920x1080, 10 frames, median of $RUNS runs (PNG in -> PNG out)"
speed() { # LABEL COMMAND...
    local label=$1; shift
    local ts=() t0 t1
    for _ in $(seq "$RUNS"); do
        rm -rf "$WORK/o_speed"; mkdir -p "$WORK/o_speed"
        t0=$(now)
        "$@" >/dev/null 2>"$WORK/err.txt" || { echo "$label FAILED"; cat "$WORK/err.txt"; return; }
        t1=$(now)
        ts+=("$(echo "$t1 - $t0" | bc)")
    done
    python3 -c "import statistics, sys; t = statistics.median(map(float, sys.argv[1:])); print(f'{\"$label\":40} {t * 100:8.0f} ms/frame')" "${ts[@]}"
}
speed "fxrun temporal_denoise (defaults)" "$FX" temporal_denoise -i "$HD/noisy/%04d.png" -o "$WORK/o_speed/%04d.png"
speed "ffmpeg hqdn3d (defaults)" ff "$HD/noisy" "$WORK/o_speed" hqdn3d
speed "ffmpeg hqdn3d=$HQ_BEST" ff "$HD/noisy" "$WORK/o_speed" "hqdn3d=$HQ_BEST"
speed "ffmpeg nlmeans=$NL_BEST" ff "$HD/noisy" "$WORK/o_speed" "nlmeans=$NL_BEST"
echo "-- fxrun stage split (last 1080p run):"
"$FX" temporal_denoise -i "$HD/noisy/%04d.png" -o "$WORK/o_speed/%04d.png" --timings 2>&1 | grep -E "stage busy|frames:" | sed 's/^/    /'
