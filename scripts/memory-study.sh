#!/usr/bin/env bash
# Peak memory of `fit-cop` and `study` against the number of listed trials (issue 31: they held
# every trial at once, 400 trials of 16 MB took 12.9 GB). Each listed trial is the synthetic walk
# (with its two plates) as a long C3D of about 16 MB, listed N times under four labs; the peak
# must not grow with N. Uses the release build.
#   bash scripts/memory-study.sh [N_FIT] [N_STUDY] [SECONDS]     (defaults 400, 40, 600 s a trial)
# The old build at bbeadbe, for comparison: KIN2GRF=/path/to/old/kin2grf bash scripts/memory-study.sh 40 8
set -euo pipefail
cd "$(dirname "$0")/.."
N_FIT=${1:-400}
N_STUDY=${2:-40}
SECONDS_TRIAL=${3:-600}
# KIN2GRF=path/to/kin2grf measures another build (the release build by default).
if [ -z "${KIN2GRF:-}" ]; then
  cmake --preset release >/dev/null
  cmake --build --preset release --target kin2grf_cli >/dev/null
fi
K=${KIN2GRF:-build/release/kin2grf}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$K" make-example --out-dir "$WORK" --seconds "$SECONDS_TRIAL" >/dev/null
TRIAL="$WORK/example_walk.c3d"
list() {  # N FILE: the walk listed N times, four labs
  for i in $(seq 1 "$1"); do echo "walking|lab$((i % 4))|walk$i|$TRIAL --mass 70"; done >"$2"
}
measure() {  # LABEL COMMAND...: peak resident memory and wall time
  local label=$1; shift
  /usr/bin/time -o "$WORK/time" -f "%M %e" "$@" >/dev/null 2>&1
  read -r kb wall <"$WORK/time"
  awk -v l="$label" -v kb="$kb" -v w="$wall" -v f="$(stat -c %s "$TRIAL")" 'BEGIN {
    printf "%-40s peak %7.1f MB  %7.1f s  (one trial file %.1f MB)\n", l, kb * 1024 / 1e6, w, f / 1e6 }'
}
list 4 "$WORK/fit4.txt"
list "$N_FIT" "$WORK/fit.txt"
measure "fit-cop, 4 trials" "$K" fit-cop --trial-list "$WORK/fit4.txt"
measure "fit-cop, $N_FIT trials" "$K" fit-cop --trial-list "$WORK/fit.txt"
list 4 "$WORK/study4.txt"
list "$N_STUDY" "$WORK/study.txt"
measure "study r, 4 trials" "$K" study r --trial-list "$WORK/study4.txt"
measure "study r, $N_STUDY trials" "$K" study r --trial-list "$WORK/study.txt"
