#!/usr/bin/env bash
# A batch of 8 mixed-size photos through glow: one fxrun process for the whole folder
# (`fxrun glow -i DIR/ -o OUT/`) against one fxrun process per photo, as a shell loop
# would run them. Prints the median of RUNS runs of each and the ratio.
#
#   bash bench/batch.sh [RUNS] [SET]   (default 3 runs, SET 1080p)
#
# Photos: 8 JPEGs of 8 different 1080p-class sizes (1920x1080, 1080x1920, 1600x1200,
# ...), cut by fxrun itself (the built-in _blit shader with OUT.SIZE: a top-left crop)
# from ../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg (5312x2988).
# SET=small: the same 8 sizes divided by 3 (640x360, ...), where the cost of starting a
# process weighs more against the GPU work.
# FXRUN=path uses that binary instead of building the release one (e.g.
# FXRUN=target/debug/fxrun for a quick look; the numbers then are not release ones).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
RUNS=${1:-3}
SET=${2:-1080p}
case "$SET" in
    1080p) SIZES="1920,1080 1080,1920 1600,1200 1440,1080 2048,1152 1280,1280 1920,1280 1366,1024" ;;
    small) SIZES="640,360 360,640 533,400 480,360 683,384 427,427 640,427 455,341" ;;
    *) echo "SET is 1080p or small"; exit 1 ;;
esac
WORK=${BENCH_DIR:-/tmp/fxgraph-batch}/$SET
PHOTO=../shared/corpus/photos/seeding_by_Clements_Engelhardt.jpg
need_files "$PHOTO"
if [ -z "${FXRUN:-}" ]; then
    cargo build --release --quiet --bin fxrun
    FXRUN="$PWD/target/release/fxrun"
fi
FX=$(realpath "$FXRUN")
echo "fxrun: $FX"
echo "adapter: $($FX --adapters | head -1)"
IN="$WORK/in"
if [ "$(ls "$IN" 2>/dev/null | wc -l)" != 8 ]; then
    rm -rf "$IN"; mkdir -p "$IN"
    i=0
    for size in $SIZES; do
        i=$((i + 1))
        printf 'EFFECT.crop = { PASS = { c = SHADER._blit { img = IN  OUT.SIZE = (%s) } } OUT = c }\n' \
            "$size" > "$WORK/crop.fx"
        "$FX" "$WORK/crop.fx" -i "$PHOTO" -o "$IN/photo_$i.jpg"
    done
fi
ls "$IN" | sed 's/^/  /' | tr '\n' ' '; echo

now() { date +%s.%N; }
one_process() {
    rm -rf "$WORK/out1"
    "$FX" glow -i "$IN/" -o "$WORK/out1/" 2>"$WORK/err.txt" || { cat "$WORK/err.txt"; exit 1; }
}
eight_processes() {
    rm -rf "$WORK/out8"; mkdir -p "$WORK/out8"
    for f in "$IN"/*.jpg; do
        "$FX" glow -i "$f" -o "$WORK/out8/$(basename "$f")" || exit 1
    done
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
: >"$WORK/t1"; : >"$WORK/t8"
for r in $(seq "$RUNS"); do
    t0=$(now); one_process; t1=$(now)
    echo "$t1 - $t0" | bc -l >>"$WORK/t1"
    t0=$(now); eight_processes; t1=$(now)
    echo "$t1 - $t0" | bc -l >>"$WORK/t8"
done
# The two ways must write the same pixels.
cmp -s <(cd "$WORK/out1" && cat *.jpg) <(cd "$WORK/out8" && cat *.jpg) \
    || { echo "the batch and the single runs differ"; exit 1; }
m1=$(median <"$WORK/t1"); m8=$(median <"$WORK/t8")
printf 'one process, 8 images:   %7.2f s (median of %d)\n' "$m1" "$RUNS"
printf '8 processes, 1 image each: %5.2f s (median of %d)\n' "$m8" "$RUNS"
printf 'ratio: %.2fx faster in one process\n' "$(echo "$m8 / $m1" | bc -l)"
grep -h "images in" "$WORK/err.txt" | sed 's/^/  last batch: /'
