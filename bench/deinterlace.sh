#!/usr/bin/env bash
# Deinterlacing: speed and quality of fxrun deinterlace (adaptive) against ffmpeg
# bwdif and yadif on the same frames, PNG sequence in -> PNG sequence out.
#
#   bash bench/deinterlace.sh [FRAMES] [RUNS]     (default 30 frames, 3 rounds)
#
# Speed: ../shared/corpus/interlaced/mpeg2_field_encoding.ts (PAL, bottom field
# first) decoded to PNG at 720x576 and scaled (interlace-aware) to 1920x1080,
# looped to FRAMES frames, into $BENCH_DIR (never into the repo). Interleaved runs
# (bench/timeit.py), medians; ffmpeg runs with 2 threads (-threads 2
# -filter_threads 2); every tool writes PNG at zlib level 1. Ratio = peer / fxrun
# (wall): above 1 means fxrun is faster. The machine load (and the CPU pressure, where
# /proc/pressure/cpu exists) is printed before and after: the timings are only
# comparable on a quiet machine. Then fxrun's stage-busy split (--timings).
#
# Quality: a camera move over ../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
# rendered at field rate and woven bottom field first (bench/deint_psnr.py, 20
# frames per size); pooled PSNR (8-bit RGB) of each tool's output against the
# progressive picture of the kept field.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
N=${1:-30}
RUNS=${2:-3}
WORK=${BENCH_DIR:-/tmp/fxgraph-deint}
CLIP=../shared/corpus/interlaced/mpeg2_field_encoding.ts
PHOTO=../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
need_files "$CLIP" "$PHOTO"
need_ffmpeg_cv
cargo build --release --quiet
FX="$PWD/target/release/fxrun"
FF="ffmpeg -v error -y -threads 2 -filter_threads 2"
echo "fxrun adapter: $($FX --adapters | head -1)"
echo "machine: $(nproc) cores, $(uname -m), $(load)"
SIZES="720x576 1920x1080"
for size in $SIZES; do
    d="$WORK/in_$size"
    if [ ! -f "$d/$(printf %04d "$N").png" ]; then
        rm -rf "$d"; mkdir -p "$d"
        ffmpeg -v error -stream_loop -1 -i "$CLIP" -frames:v "$N" \
            -vf "scale=${size%x*}:${size#*x}:interl=1,setfield=bff" -start_number 1 "$d/%04d.png"
    fi
    q="$WORK/q_$size"
    [ -f "$q/truth/0020.png" ] || python3 bench/deint_psnr.py make "$PHOTO" "${size%x*}" "${size#*x}" 20 "$q"
done
for size in $SIZES; do
    in="$WORK/in_$size/%04d.png"
    out="$WORK/out_$size"; rm -rf "$out"; mkdir -p "$out"
    echo "speed, $size, $N frames (ref: fxrun adaptive)"
    python3 bench/timeit.py "$RUNS" "fxrun adaptive" \
        "fxrun adaptive" "$FX deinterlace --set mode=adaptive --set field_order=bff -i $in -o $out/f%04d.png" \
        "ffmpeg bwdif (2 threads)" "$FF -i $in -vf bwdif=mode=0:parity=bff -compression_level 1 $out/b%04d.png" \
        "ffmpeg yadif (2 threads)" "$FF -i $in -vf yadif=mode=0:parity=bff -compression_level 1 $out/y%04d.png"
    echo "  after the rounds: $(load)"
    "$FX" deinterlace --set mode=adaptive --set field_order=bff -i "$in" -o "$out/t%04d.png" --timings 2>&1 |
        grep -E "stage busy|frames:|deinterlace/" | sed "s/^/    /"
    q="$WORK/q_$size"
    qin="$q/in/%04d.png"
    rm -rf "$q/out"; mkdir -p "$q/out"
    "$FX" deinterlace --set mode=adaptive --set field_order=bff -i "$qin" -o "$q/out/f%04d.png" >/dev/null
    $FF -i "$qin" -vf bwdif=mode=0:parity=bff -compression_level 1 "$q/out/b%04d.png"
    $FF -i "$qin" -vf yadif=mode=0:parity=bff -compression_level 1 "$q/out/y%04d.png"
    echo "quality, $size (PSNR against the progressive truth, 20 frames):" \
        "fxrun adaptive $(python3 bench/deint_psnr.py score "$q" "$q/out/f%04d.png") dB," \
        "bwdif $(python3 bench/deint_psnr.py score "$q" "$q/out/b%04d.png") dB," \
        "yadif $(python3 bench/deint_psnr.py score "$q" "$q/out/y%04d.png") dB"
done
