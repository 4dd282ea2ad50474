#!/usr/bin/env bash
# How much of a RetroArch slang collection runs in fxrun on this machine:
#   bench/slang_coverage.sh DIR [FXRUN]
# walks DIR for *.slangp and, for each preset, asks fxrun to
#   1. parse it and its shaders    (fails: "cannot parse the preset", "cannot preprocess")
#   2. translate every pass to WGSL and check it (`fxrun P --check --size 64x64`, the size step 3 renders)
#   3. render one frame of a 64x64 image (`fxrun P -i in.png -o out.png`)
# and prints the counts, with the failures by class (the phrase of the message).
# FXRUN defaults to target/release/fxrun (build it first: cargo build --release).
# Needs a Vulkan adapter for step 3 (lavapipe is enough) and ffmpeg for the input.
set -uo pipefail
dir=${1:?usage: bench/slang_coverage.sh DIR [FXRUN]}
fxrun=${2:-$(dirname "$0")/../target/release/fxrun}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ffmpeg -v error -f lavfi -i testsrc2=size=64x64 -frames:v 1 "$work/in.png"

classify() {
    # The failure class of an fxrun error message (stdin).
    local m
    m=$(cat)
    case "$m" in
        *"cannot parse the preset"*) echo "parse: preset" ;;
        *"cannot preprocess"*) echo "parse: preprocess" ;;
        *"GLSL error"*) echo "translate: GLSL (glslang)" ;;
        *"cannot translate to WGSL (matrix varying)"*) echo "translate: matrix varying" ;;
        *"cannot translate to WGSL (float16)"*) echo "translate: float16" ;;
        *"cannot translate to WGSL (special type"*) echo "translate: naga special type not registered" ;;
        *"cannot translate to WGSL"*) echo "translate: naga (other)" ;;
        *"unknown semantic"*) echo "translate: unknown semantic" ;;
        *"is not supported"*) echo "translate: unsupported: $(printf '%s' "$m" | sed -n 's/.*: \(.*\) is not supported.*/\1/p' | head -1 | sed 's/`[^`]*`/X/g; s/[0-9]\+/N/g')" ;;
        *) echo "other: $(printf '%s' "$m" | grep -m1 -o 'error[^`]*' | cut -c1-70)" ;;
    esac
}

total=0 parsed=0 translated=0 rendered=0
: > "$work/classes"
while IFS= read -r -d '' p; do
    total=$((total + 1))
    if check=$("$fxrun" "$p" --check --size 64x64 2>&1 >/dev/null); then
        parsed=$((parsed + 1)); translated=$((translated + 1))
        if run=$("$fxrun" "$p" -i "$work/in.png" -o "$work/out.png" 2>&1 >/dev/null); then
            rendered=$((rendered + 1))
        else
            echo "render: $(printf '%s' "$run" | classify)" >> "$work/classes"
        fi
    else
        class=$(printf '%s' "$check" | classify)
        case "$class" in parse:*) ;; *) parsed=$((parsed + 1)) ;; esac
        echo "$class" >> "$work/classes"
        [ -n "${VERBOSE:-}" ] && echo "$p: $class" >&2
    fi
done < <(find "$dir" -name '*.slangp' -print0 | sort -z)

echo "collection: $dir"
echo "presets:    $total"
echo "parse:      $parsed"
echo "translate:  $translated"
adapter=$("$fxrun" --adapters 2>/dev/null | head -1)
echo "render:     $rendered (one frame, 64x64, on $adapter)"
echo "failures by class:"
sort "$work/classes" | uniq -c | sort -rn
