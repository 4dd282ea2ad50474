#!/usr/bin/env bash
# Regenerates the librashader references of tests/slang.rs (run once; the PNGs are
# committed, so CI needs neither librashader nor this script):
#   tests/slang/make_refs.sh [CORPUS] [LIBRASHADER_CLI]
# CORPUS: the permissively licensed presets (default ../shared/corpus/slang);
# LIBRASHADER_CLI: librashader-cli 0.12.1 built with `--features vulkan,wgpu`
# (cargo install librashader-cli --version 0.12.1 --features vulkan,wgpu).
# For each preset of CORPUS/presets.json, renders tests/slang/input.png with
# librashader's Vulkan runtime (lavapipe is enough) at frame 0 into
# tests/slang/refs/<preset path with / as __>.png, and lists the presets it
# could not render in tests/slang/refs/FAILED.txt.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
corpus=${1:-$here/../../../shared/corpus/slang}
cli=${2:-librashader-cli}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
# The input: 96x64, ffmpeg's testsrc2 (colour bars, gradients, text, a moving
# disc), one frame; the sequence for the temporal tests is made by the tests.
[ -f "$here/input.png" ] || ffmpeg -v error -f lavfi -i testsrc2=size=96x64 -frames:v 1 "$here/input.png"
mkdir -p "$here/refs"
: > "$here/refs/FAILED.txt"
python3 -c "import json,sys; [print(p[0]) for p in json.load(open(sys.argv[1]))]" "$corpus/presets.json" |
while IFS= read -r p; do
    name=$(printf '%s' "${p%.slangp}" | sed 's#/#__#g; s/ /_/g')
    if ! "$cli" render --runtime vulkan --preset "$corpus/$p" --image "$here/input.png" \
        --out "$here/refs/$name.png" --frame 0 > "$here/refs/$name.log" 2>&1; then
        echo "$p: $(tail -1 "$here/refs/$name.log")" >> "$here/refs/FAILED.txt"
        rm -f "$here/refs/$name.png"
    fi
    rm -f "$here/refs/$name.log"
done
echo "references: $(ls "$here/refs"/*.png | wc -l); failed: $(wc -l < "$here/refs/FAILED.txt")"
