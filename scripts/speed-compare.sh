#!/usr/bin/env bash
# Two release builds' speed, side by side: this VM's speed swings by up to half within the hour,
# so figures are only comparable when taken in the same minutes. ROUNDS times, alternating the
# builds: the benchmarks on Rajagopal's walk (per-frame solve, pipeline; one thread) and the
# command-line tool end to end (`kin2grf estimate` on Rajagopal's treadmill run, 510 frames, as
# scripts/e2e-speed.sh times it). Prints the median and the best of each.
#   bash scripts/speed-compare.sh OLD_BUILD_DIR NEW_BUILD_DIR [ROUNDS=3] [DATA_DIR]
# (a build dir: build/release, or a copy of an older one, e.g. `cp -r build/release /tmp/old`)
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=$1 NEW=$2 ROUNDS=${3:-3} DATA=${4:-../shared/data}
for b in "$OLD" "$NEW"; do
  [ -x "$b/kin2grf" ] && [ -x "$b/bench/kin2grf_bench" ] || { echo "speed-compare: $b has no kin2grf and bench/kin2grf_bench" >&2; exit 2; }
done
[ -d "$DATA/rajagopal2016_treadmill_run" ] || { echo "speed-compare: no shared data in $DATA" >&2; exit 2; }
/usr/bin/python3 - "$OLD" "$NEW" "$ROUNDS" "$(cd "$DATA" && pwd)" <<'PY'
import collections, json, os, statistics, subprocess, sys, tempfile, time
old, new, rounds, data = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
env = dict(os.environ, KIN2GRF_THREADS="1", KIN2GRF_DATA_DIR=data)
d = f"{data}/rajagopal2016_treadmill_run"
out = tempfile.mkdtemp()
res = collections.defaultdict(list)
for _ in range(rounds):
    for b in (old, new):
        bench = subprocess.run([f"{b}/bench/kin2grf_bench", "--benchmark_filter=real:1", "--benchmark_repetitions=3",
                                "--benchmark_format=json"], capture_output=True, text=True, env=env, check=True).stdout
        for bm in json.loads(bench)["benchmarks"]:
            if bm.get("run_type") == "iteration":
                res[(bm["run_name"], b)].append(bm["frames_per_s"])
        cmd = [f"{b}/kin2grf", "estimate", f"{d}/motion_capture_run.trc", "--static", f"{d}/static_run.trc",
               "--mass", "72.84", "-o", f"{out}/grf.mot"]
        for _ in range(20):
            t = time.perf_counter()
            subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            res[("estimate end to end (510 frames)", b)].append(510 / (time.perf_counter() - t))
for (name, b), v in sorted(res.items(), key=lambda kv: (kv[0][0], kv[0][1] != old)):
    print(f"{name:40s} {'old' if b == old else 'new'}  median {statistics.median(v):9,.0f}  best {max(v):9,.0f} frames/s  (n={len(v)})")
PY
