#!/usr/bin/env bash
# End-to-end speed of the command-line tool, timed from outside the process (issue 11):
# `kin2grf estimate` on Rajagopal's treadmill run (TRC + static TRC, 510 frames), and
# `kin2grf --version` (the process's start alone). Medians of N runs (default 40).
#   bash scripts/e2e-speed.sh [KIN2GRF] [N] [DATA_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
EXE=${1:-build/release/kin2grf} N=${2:-40} DATA=${3:-../shared/data}
D="$DATA/rajagopal2016_treadmill_run"
[ -x "$EXE" ] || { echo "e2e-speed: no executable $EXE (cmake --preset release && cmake --build --preset release)" >&2; exit 2; }
[ -f "$D/motion_capture_run.trc" ] || { echo "e2e-speed: $D not found" >&2; exit 2; }
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
/usr/bin/python3 - "$EXE" "$N" "$D" "$OUT" <<'PY'
import statistics, subprocess, sys, time
exe, n, d, out = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
runs = {
    "estimate (510 frames)": [exe, "estimate", f"{d}/motion_capture_run.trc", "--static", f"{d}/static_run.trc",
                              "--mass", "72.84", "-o", f"{out}/run_grf.mot"],
    "--version (start-up)": [exe, "--version"],
}
for name, cmd in runs.items():
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        ts.append(time.perf_counter() - t)
    m = statistics.median(ts)
    rate = f", {510 / m:,.0f} frames/s" if "estimate" in name else ""
    print(f"{name:24s} median {1e3 * m:6.1f} ms (min {1e3 * min(ts):.1f}, max {1e3 * max(ts):.1f}){rate}")
PY
