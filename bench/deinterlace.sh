#!/usr/bin/env bash
# Deinterlacing throughput: fxrun deinterlace (adaptive, bob) against ffmpeg yadif
# and bwdif on the same frames, PNG sequence in -> PNG sequence out, in one run.
#
#   bash bench/deinterlace.sh [FRAMES]      (default 50 frames per size)
#
# Frames: ../shared/corpus/interlaced/mpeg2_field_encoding.ts (PAL, bottom field
# first), decoded to PNG at 720x576 and scaled (interlace-aware) to 1920x1080,
# looped to FRAMES frames. ffmpeg runs with 2 threads (-threads 2 -filter_threads 2);
# both write PNG at compression level 1. fxrun also prints its stage-busy split.
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-50}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
WORK=${BENCH_DIR:-/tmp/fxgraph-deint}
CLIP=../shared/corpus/interlaced/mpeg2_field_encoding.ts
[ -f "$CLIP" ] || { echo "missing $CLIP"; exit 1; }
command -v ffmpeg >/dev/null || { echo "install ffmpeg"; exit 1; }
cargo build --release --quiet
FX="$PWD/target/release/fxrun"
echo "fxrun adapter: $($FX --adapters | head -1)"
for size in 720x576 1920x1080; do
    d="$WORK/in_$size"
    if [ ! -f "$d/$(printf %04d "$N").png" ]; then
        rm -rf "$d"; mkdir -p "$d"
        ffmpeg -v error -stream_loop -1 -i "$CLIP" -frames:v "$N" \
            -vf "scale=${size%x*}:${size#*x}:interl=1,setfield=bff" -start_number 1 "$d/%04d.png"
    fi
done
time_it() { # label size command...
    local label=$1 size=$2; shift 2
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>"$WORK/err.txt" || { echo "$label $size FAILED"; cat "$WORK/err.txt"; return; }
    t1=$(date +%s.%N)
    python3 -c "t=$t1-$t0; print(f'{\"$label\":30} {\"$size\":10} {t*1000:9.0f} ms  {$N/t:7.1f} fps')"
}
for size in 720x576 1920x1080; do
    in="$WORK/in_$size/%04d.png"
    out="$WORK/out_$size"; rm -rf "$out"; mkdir -p "$out"
    time_it "ffmpeg yadif (bff, 2 thr)" "$size" ffmpeg -v error -y -threads 2 -filter_threads 2 -i "$in" -vf "yadif=mode=0:parity=bff" -compression_level 1 "$out/y%04d.png"
    time_it "ffmpeg bwdif (bff, 2 thr)" "$size" ffmpeg -v error -y -threads 2 -filter_threads 2 -i "$in" -vf "bwdif=mode=0:parity=bff" -compression_level 1 "$out/b%04d.png"
    time_it "fxrun deinterlace adaptive" "$size" "$FX" deinterlace --set mode=adaptive --set field_order=bff -i "$in" -o "$out/f%04d.png"
    time_it "fxrun deinterlace bob" "$size" "$FX" deinterlace --set mode=bob --set field_order=bff -i "$in" -o "$out/o%04d.png"
    "$FX" deinterlace --set mode=adaptive --set field_order=bff -i "$in" -o "$out/t%04d.png" --timings 2>&1 | grep -E "stage busy|frames:" | sed "s/^/    $size /"
done
