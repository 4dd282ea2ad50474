#!/usr/bin/env bash
# GPU time of the ssgi effect against ssao at 1920x1080 on builtin:room: each
# effect runs in its own fxrun process over a 3-frame still sequence (--frames 0..2:
# the last frame's pass timings, after the pipelines and lavapipe's shader JIT are
# warm), ROUNDS rounds interleaved so both see the same machine load; prints the
# median GPU ms of each effect's passes (timestamp queries, fxrun --timings-json)
# and the load average before and after.
#
#   bash bench/ssgi.sh [ROUNDS]      (default 3)
#
# Environment (optional): FX_BENCH_SIZE=WxH (default 1920x1080), FXRUN (default
# target/release/fxrun, built if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
ROUNDS=${1:-3}
SIZE=${FX_BENCH_SIZE:-1920x1080}
FXRUN=${FXRUN:-target/release/fxrun}
[ -x "$FXRUN" ] || cargo build --release --quiet
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "machine: $(nproc) cores, adapter: $("$FXRUN" --adapters 2>&1 | head -1)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 "$ROUNDS"); do
    for fx in ssao ssgi "ssgi --set ssgi.directions=4 --set ssgi.steps=8"; do
        tag=$(printf '%s' "$fx" | tr -c 'a-z0-9' '_')
        # shellcheck disable=SC2086
        "$FXRUN" $fx --scene builtin:room --size "$SIZE" --frames 0..2 \
            -o "$tmp/$tag-%04d.png" --timings --timings-json "$tmp/$tag-$r.json" >/dev/null
    done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$tmp" "$SIZE" <<'PY'
import glob, json, statistics, sys
tmp, size = sys.argv[1], sys.argv[2]
labels = {"ssao": "ssao", "ssgi": "ssgi (defaults: 8 directions x 12 steps)",
          "ssgi___set_ssgi_directions_4___set_ssgi_steps_8": "ssgi (4 directions x 8 steps)"}
print(f"| effect at {size} | median GPU ms | per pass (median) | rounds |")
print("|---|---|---|---|")
for tag, label in labels.items():
    runs = [json.load(open(f))["passes"] for f in sorted(glob.glob(f"{tmp}/{tag}-*.json"))]
    total = statistics.median(sum(p["gpu_ms"] for p in r) for r in runs)
    names = [p["path"] for p in runs[0]]
    per = ", ".join(f"{n} {statistics.median(r[i]['gpu_ms'] for r in runs):.0f}" for i, n in enumerate(names))
    print(f"| {label} | {total:.0f} | {per} | {len(runs)} |")
PY
