#!/usr/bin/env bash
# Whole-process timing of fxrun against CPU peers on the same photos, in one run:
# Gaussian blur sigma 8 and glow, PNG -> PNG, at 1920x1080 and 3840x2160.
#
#   bash bench/compare.sh [RUNS]        (default 10 runs each, hyperfine medians)
#
# Needs: hyperfine, vips (libvips-tools), ImageMagick 6 (convert-im6.q16), ffmpeg,
# python3 with opencv-python-headless and numpy. Missing peers are skipped.
# The input photo is ../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
# (CC0), resized once with vips. fxrun runs on the adapter it picks by default
# (set WGPU_BACKEND or pass FXRUN_ARGS="--adapter N" to choose).
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-10}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
WORK=${BENCH_DIR:-/tmp/fxgraph-bench}
mkdir -p "$WORK"
PHOTO=../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
[ -f "$PHOTO" ] || { echo "missing $PHOTO"; exit 1; }
command -v hyperfine >/dev/null || { echo "install hyperfine (apt-get install hyperfine)"; exit 1; }
cargo build --release --quiet
FX="$PWD/target/release/fxrun ${FXRUN_ARGS:-}"
IM=$(command -v convert-im6.q16 || true)

for size in 1920x1080 3840x2160; do
    [ -f "$WORK/in_$size.png" ] || vips thumbnail "$PHOTO" "$WORK/in_$size.png" "${size%x*}" --height "${size#*x}" --size force
done

adapter=$($FX --adapters | head -1)
echo "fxrun adapter: $adapter"
echo "machine: $(nproc) cores, $(uname -m)"

results="$WORK/results.txt"
: > "$results"
bench() { # name size command...
    local name=$1 size=$2; shift 2
    hyperfine -N --warmup 1 --runs "$RUNS" --export-json "$WORK/h.json" "$*" >/dev/null 2>&1 || { echo "$name $size FAILED: $*"; return; }
    local med
    med=$(python3 -c "import json;print(round(json.load(open('$WORK/h.json'))['results'][0]['median']*1000,1))")
    printf '%-28s %-10s %8s ms\n' "$name" "$size" "$med" | tee -a "$results"
}

for size in 1920x1080 3840x2160; do
    in="$WORK/in_$size.png"
    bench "fxrun gaussian_blur s8" "$size" $FX gaussian_blur --set sigma=8 -i "$in" -o "$WORK/fx_blur.png"
    command -v vips >/dev/null && bench "vips gaussblur 8" "$size" vips gaussblur "$in" "$WORK/vips_blur.png[compression=1]" 8
    # -blur is ImageMagick's separable Gaussian (-gaussian-blur, a 2D kernel, took 16 s at 1080p here).
    [ -n "$IM" ] && bench "imagemagick -blur 0x8" "$size" "$IM" "$in" -define png:compression-level=1 -blur 0x8 "$WORK/im_blur.png"
    command -v ffmpeg >/dev/null && bench "ffmpeg gblur sigma=8" "$size" ffmpeg -v error -y -i "$in" -vf gblur=sigma=8 -compression_level 1 "$WORK/ff_blur.png"
    python3 -c "import cv2" 2>/dev/null && bench "opencv GaussianBlur" "$size" python3 bench/blur_opencv.py "$in" "$WORK/cv_blur.png" 8
    bench "fxrun glow" "$size" $FX glow -i "$in" -o "$WORK/fx_glow.png"
    python3 -c "import cv2" 2>/dev/null && bench "opencv glow script" "$size" python3 bench/glow_opencv.py "$in" "$WORK/cv_glow.png"
done

echo
echo "ratios (peer time / fxrun time; > 1 means fxrun is faster):"
python3 - "$results" <<'PY'
import sys, collections
rows = [l.rsplit(None, 2) for l in open(sys.argv[1]) if l.strip()]
t = {}
for r in rows:
    name_size, ms, _ = r
    name, size = name_size.rsplit(None, 1)
    t[(name.strip(), size)] = float(ms)
for size in sorted({s for _, s in t}):
    for fx, kind in (("fxrun gaussian_blur s8", "blur"), ("fxrun glow", "glow")):
        if (fx, size) not in t:
            continue
        for (name, s), ms in t.items():
            if s == size and name != fx and not name.startswith("fxrun") and (("glow" in name) == (kind == "glow")):
                print(f"  {size} {kind:5} {name:28} {ms / t[(fx, size)]:.2f}x")
PY
