#!/usr/bin/env bash
# How a batch of trials scales from one core to two (issue 11: >= 1.8 x), timed from outside:
# the development trials six times over (84 trials), ROUNDS times, alternating
#   one process, one job:        kin2grf batch ALL --jobs 1
#   two processes, one job each: kin2grf batch HALF --jobs 1 (twice at once, each half the list)
#   one process, two jobs:       kin2grf batch ALL --jobs 2
# with KIN2GRF_THREADS=1 (one job, one thread). This VM's speed swings by a quarter from one run
# to the next, so it prints each round's times, the medians and the ratio of the medians.
#   bash scripts/batch-speed.sh [ROUNDS=8] [KIN2GRF=build/release/kin2grf] [DATA_DIR=../shared/data]
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${1:-8} EXE=${2:-build/release/kin2grf} DATA=${3:-../shared/data}
[ -x "$EXE" ] || { echo "batch-speed: no executable $EXE (cmake --preset release && cmake --build --preset release)" >&2; exit 2; }
[ -d "$DATA" ] || { echo "batch-speed: no data folder $DATA" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
grep -v '^#' scripts/trials.txt | grep . | sed "s#DATA#$DATA#g" > "$WORK/once.txt"
for _ in 1 2 3; do cat "$WORK/once.txt"; done > "$WORK/half.txt"
cat "$WORK/half.txt" "$WORK/half.txt" > "$WORK/all.txt"
/usr/bin/python3 - "$EXE" "$ROUNDS" "$WORK" <<'PY'
import os, statistics, subprocess, sys, time
exe, rounds, work = sys.argv[1], int(sys.argv[2]), sys.argv[3]
env = dict(os.environ, KIN2GRF_THREADS="1")
def run(*cmds):
    t = time.perf_counter()
    ps = [subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env) for c in cmds]
    for p in ps:
        p.wait()  # a failing trial makes batch exit 1; the timing stands
    return time.perf_counter() - t
one = [exe, "batch", f"{work}/all.txt", "--jobs", "1"]
half = [exe, "batch", f"{work}/half.txt", "--jobs", "1"]
two = [exe, "batch", f"{work}/all.txt", "--jobs", "2"]
res = {"one process": [], "two processes": [], "two jobs": []}
print(f"{'round':>5} {'1 process':>10} {'2 processes':>12} {'2 jobs':>8}   (s, 84 trials)")
for r in range(rounds):
    res["one process"].append(run(one))
    res["two processes"].append(run(half, half))
    res["two jobs"].append(run(two))
    print(f"{r + 1:5d} {res['one process'][-1]:10.2f} {res['two processes'][-1]:12.2f} {res['two jobs'][-1]:8.2f}")
m = {k: statistics.median(v) for k, v in res.items()}
print(f"median {m['one process']:9.2f} {m['two processes']:12.2f} {m['two jobs']:8.2f}")
print(f"two processes: {m['one process'] / m['two processes']:.2f} x one; two jobs (threads): "
      f"{m['one process'] / m['two jobs']:.2f} x one (ratios of the medians)")
PY
