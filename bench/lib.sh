# Shared by the bench scripts: `. "$(dirname "$0")/lib.sh"` right after
# `set -euo pipefail`. It moves to the repository root and gives the GPU runs a
# runtime directory; its functions check what a bench needs and describe the
# machine. Not a script of its own.
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}

# need_files FILE...: stops with "missing FILE" where one is absent (the corpus
# lies in ../shared/corpus).
need_files() {
    for f in "$@"; do
        [ -f "$f" ] || { echo "missing $f"; exit 1; }
    done
}

# need_ffmpeg_cv: stops unless ffmpeg and python3 with OpenCV and numpy are there.
need_ffmpeg_cv() {
    command -v ffmpeg >/dev/null || { echo "install ffmpeg"; exit 1; }
    python3 -c "import cv2, numpy" 2>/dev/null || { echo "install python3 opencv-python-headless and numpy"; exit 1; }
}

# load: the load averages and, where /proc/pressure/cpu exists, the CPU pressure:
# timings are only comparable on a quiet machine.
load() {
    echo "load $(cut -d' ' -f1-3 /proc/loadavg)$(sed -n 's/^some avg10=\([^ ]*\) avg60=\([^ ]*\).*/, cpu pressure (PSI some) 10 s: \1 %, 60 s: \2 %/p' /proc/pressure/cpu 2>/dev/null)"
}

# test_binary FILE: the test binary holding tests/FILE.rs: tests/scene and
# tests/engine gather most files as modules (Cargo.toml); the others are their own.
test_binary() {
    local b
    for b in scene engine; do
        grep -qx "mod $1;" "tests/$b/main.rs" && { echo "$b"; return; }
    done
    echo "$1"
}

# report_test REPORT FILE NAME: runs the ignored test NAME of tests/FILE.rs in
# release mode; it prints its Markdown report and writes it to $FX_BENCH_OUT
# (default target/REPORT).
report_test() {
    export FX_BENCH_OUT="${FX_BENCH_OUT:-$PWD/target/$1}"
    mkdir -p "$(dirname "$FX_BENCH_OUT")"
    local bin name=$3
    bin=$(test_binary "$2")
    [ "$bin" != "$2" ] && name="$2::$3"
    cargo test --release --test "$bin" -- --ignored --exact "$name" --nocapture
}
