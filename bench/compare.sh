#!/usr/bin/env bash
# Whole-process timing of fxrun against CPU tools on the same photo, PNG -> PNG:
# Gaussian blur sigma 8 (vips gaussblur, OpenCV, ffmpeg gblur, ImageMagick -blur)
# and glow (an OpenCV script), interleaved runs, medians.
#
#   bash bench/compare.sh [RUNS]        (default 5 rounds after one warm-up)
#   SIZES="1920x1080 3840x2160" bash bench/compare.sh    (default: 1920x1080)
#
# Needs python3 (bench/timeit.py). Optional peers, skipped when missing: vips
# (libvips-tools), python3 with opencv-python and numpy, ffmpeg, ImageMagick 6
# (convert-im6.q16). The photo is ../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
# (CC0), resized once with vips or OpenCV into $BENCH_DIR (never into the repo).
# Every tool writes PNG at zlib level 1. fxrun uses the adapter it picks by default
# (WGPU_BACKEND or FXRUN_ARGS="--adapter N" to choose). Ratio = peer / fxrun (wall):
# above 1 means fxrun is faster.
#
# fxrun's gaussian_blur blurs in linear light (8-bit files are decoded from sRGB
# and encoded back); vips, OpenCV, ffmpeg and ImageMagick blur the stored values.
# `fxrun --assume-linear` does the same maths as they do (it matches OpenCV within
# 1 LSB, tests/effects/gaussian_blur.rs) and is timed too. vips gaussblur's defaults cut the
# kernel where it falls below 0.2 of its peak and use integer weights (up to 10 LSB
# off OpenCV on the photo); it is also timed with OpenCV's kernel extent
# (--min-ampl 0.011, i.e. exp(-4.5) at 3 sigma), in integer and float precision.
# After the timings, bench/blur_accuracy.py prints each output's agreement with
# OpenCV.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
RUNS=${1:-5}
SIZES=${SIZES:-1920x1080}
WORK=${BENCH_DIR:-/tmp/fxgraph-bench}
mkdir -p "$WORK"
PHOTO=../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
need_files "$PHOTO"
cargo build --release --quiet
FX="$PWD/target/release/fxrun ${FXRUN_ARGS:-}"
have() { command -v "$1" >/dev/null; }
CV=0; python3 -c "import cv2, numpy" 2>/dev/null && CV=1
IM=$(command -v convert-im6.q16 || true)

for size in $SIZES; do
    w=${size%x*} h=${size#*x} f="$WORK/in_$size.png"
    [ -f "$f" ] && continue
    if have vips; then
        vips thumbnail "$PHOTO" "$f" "$w" --height "$h" --size force
    else
        python3 -c "import cv2,sys; cv2.imwrite(sys.argv[2], cv2.resize(cv2.imread(sys.argv[1]), ($w, $h), interpolation=cv2.INTER_AREA))" "$PHOTO" "$f"
    fi
done

echo "fxrun adapter: $($FX --adapters | head -1)"
echo "machine: $(nproc) cores, $(uname -m), $(load)"
for size in $SIZES; do
    in="$WORK/in_$size.png"
    echo "gaussian blur sigma 8, $size (ref: fxrun)"
    args=(fxrun "$FX gaussian_blur --set sigma=8 -i $in -o $WORK/fx_blur.png"
          "fxrun --assume-linear" "$FX gaussian_blur --assume-linear --set sigma=8 -i $in -o $WORK/fx_blur_al.png")
    have vips && args+=("vips gaussblur 8" "vips gaussblur $in $WORK/vips_blur.png[compression=1] 8"
        "vips gaussblur 8, min-ampl 0.011" "vips gaussblur $in $WORK/vips_blur_i.png[compression=1] 8 --min-ampl 0.011"
        "vips gaussblur 8, min-ampl 0.011 float" "vips gaussblur $in $WORK/vips_blur_f.png[compression=1] 8 --min-ampl 0.011 --precision float")
    [ $CV = 1 ] && args+=("opencv GaussianBlur (python)" "python3 bench/blur_opencv.py $in $WORK/cv_blur.png 8")
    have ffmpeg && args+=("ffmpeg gblur sigma=8" "ffmpeg -v error -y -i $in -vf gblur=sigma=8 -compression_level 1 $WORK/ff_blur.png")
    # -blur is ImageMagick's separable Gaussian (-gaussian-blur, a 2D kernel, is far slower).
    [ -n "$IM" ] && args+=("imagemagick -blur 0x8" "$IM $in -define png:compression-level=1 -blur 0x8 $WORK/im_blur.png")
    python3 bench/timeit.py "$RUNS" fxrun "${args[@]}"
    if [ $CV = 1 ]; then
        echo "agreement with OpenCV GaussianBlur on the stored values, $size"
        python3 bench/blur_accuracy.py "$in" 8 "fxrun --assume-linear=$WORK/fx_blur_al.png" \
            "vips gaussblur 8=$WORK/vips_blur.png" "vips min-ampl 0.011=$WORK/vips_blur_i.png" \
            "vips min-ampl 0.011 float=$WORK/vips_blur_f.png" "ffmpeg gblur sigma=8=$WORK/ff_blur.png" \
            "imagemagick -blur 0x8=$WORK/im_blur.png"
    fi
    echo "glow, $size (ref: fxrun glow)"
    args=("fxrun glow" "$FX glow -i $in -o $WORK/fx_glow.png")
    [ $CV = 1 ] && args+=("opencv glow script (python)" "python3 bench/glow_opencv.py $in $WORK/cv_glow.png")
    python3 bench/timeit.py "$RUNS" "fxrun glow" "${args[@]}"
done
