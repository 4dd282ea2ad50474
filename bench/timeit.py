#!/usr/bin/env python3
"""Interleaved whole-process timings for the bench scripts (no hyperfine needed).

  timeit.py RUNS REF LABEL1 CMD1 LABEL2 CMD2 ...

Runs every command once per round, RUNS rounds (one warm-up round first, not
counted), so that the peers see the same machine load. Prints per label the
median wall time, the median CPU time (user + system of the process and its
threads) and, for every label but REF, the ratio median(label) / median(REF) of
the wall times: above 1 means REF is faster. A failing command aborts.
"""
import resource
import statistics
import subprocess
import sys
import time


def run(cmd):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, shell=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    t1 = time.perf_counter()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit(f"FAILED ({p.returncode}): {cmd}\n{p.stderr.decode(errors='replace')}")
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return t1 - t0, cpu


def main():
    runs, ref = int(sys.argv[1]), sys.argv[2]
    items = list(zip(sys.argv[3::2], sys.argv[4::2]))
    times = {label: ([], []) for label, _ in items}
    for _, cmd in items:
        run(cmd)
    for _ in range(runs):
        for label, cmd in items:
            w, c = run(cmd)
            times[label][0].append(w)
            times[label][1].append(c)
    med = {label: statistics.median(w) for label, (w, _) in times.items()}
    for label, (w, c) in times.items():
        ratio = "" if label == ref else f"  ratio {med[label] / med[ref]:5.2f}x"
        print(f"  {label:36} {med[label] * 1000:8.0f} ms  cpu {statistics.median(c) * 1000:7.0f} ms{ratio}"
              f"   (runs: {' '.join(str(round(x * 1000)) for x in w)})", flush=True)


if __name__ == "__main__":
    main()
