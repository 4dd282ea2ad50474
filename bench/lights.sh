#!/usr/bin/env bash
# Many lights: whole-process time of `fxrun --scene` (load, render, PNG encode)
# and the GPU time of the light pass, against the number of random point lights
# (1, 32, 128, 512, 1024; radii 4–10 % of the scene diagonal), per technique and
# light-culling method, at 1920x1080 on the Cornell box of ../shared/corpus.
# Medians of RUNS runs (default 3), all in one run of this script.
#
#   bash bench/lights.sh [RUNS]
#
# Environment (optional): FX_BENCH_SCENE (default the Cornell box),
# FX_BENCH_LIGHTS="1 32 128 512 1024", FX_BENCH_TECHNIQUES="deferred light-prepass forward",
# FX_BENCH_CULLING="clustered volumes", FX_BENCH_SIZE=1920x1080, FXRUN_ARGS (e.g. --shadows off).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
RUNS=${1:-3}
SCENE=${FX_BENCH_SCENE:-../shared/corpus/gltf/CornellBox.glb}
LIGHTS=${FX_BENCH_LIGHTS:-1 32 128 512 1024}
TECHNIQUES=${FX_BENCH_TECHNIQUES:-deferred light-prepass forward}
CULLING=${FX_BENCH_CULLING:-clustered volumes}
SIZE=${FX_BENCH_SIZE:-1920x1080}
WORK=${BENCH_DIR:-/tmp/fxgraph-bench}
mkdir -p "$WORK"
need_files "$SCENE"
cargo build --release --quiet --bin fxrun
FX="$PWD/target/release/fxrun ${FXRUN_ARGS:-}"

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

echo "adapter: $($FX --adapters 2>/dev/null | head -1)"
echo "scene: $SCENE at $SIZE, medians of $RUNS runs; whole process ms (light pass GPU ms)"
echo
header="| technique | culling |"; rule="|---|---|"
for n in $LIGHTS; do header+=" $n |"; rule+="---|"; done
echo "$header ratio 1024/1 |"; echo "$rule---|"
for t in $TECHNIQUES; do
    for c in $CULLING; do
        [ "$t" = forward ] && [ "$c" = volumes ] && c_label="volumes (all lights per fragment)" || c_label=$c
        row="| $t | $c_label |"; first=""; last=""
        for n in $LIGHTS; do
            walls=(); lights=()
            for _ in $(seq "$RUNS"); do
                start=$(date +%s%N)
                out=$($FX --scene "$SCENE" --environment none --lights "$n" --renderer "$t" --light-culling "$c" \
                    --size "$SIZE" --timings -o "$WORK/lights_${t}_${c}_$n.png" 2>&1)
                end=$(date +%s%N)
                walls+=($(( (end - start) / 1000000 )))
                lights+=($(echo "$out" | awk '/render lights/ {print $(NF-1)}' | head -1))
            done
            w=$(printf '%s\n' "${walls[@]}" | median)
            l=$(printf '%s\n' "${lights[@]:-0}" | median)
            [ -z "$first" ] && first=$w; last=$w
            row+=" $w ($l) |"
        done
        echo "$row $(awk -v a="$last" -v b="$first" 'BEGIN {printf "%.2f", a / b}') |"
    done
done
