#!/usr/bin/env bash
# Run the paper's studies (kin2grf study) on every development trial with plates and write their
# tables, JSON and HTML reports to out/study/.
#   bash scripts/study-all.sh [DATA_DIR] [KIND...]     (default kinds: all of them)
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-../shared/data}
shift || true
KINDS=("$@")
[ ${#KINDS[@]} -gt 0 ] || KINDS=(r ground-shift cutoff post-cutoff-cycles kinematic-cutoff speed-gate speed-gate-ratio noise marker-rate marker-labels min-kinematic-cycles split-distance torso-length torso-lag thigh-lag torso-vertical-cutoff running-sway-gain double-support-sta double-support-angle foot-model plate-export)
[ -d "$DATA" ] || { echo "study-all: no data folder $DATA" >&2; exit 1; }
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
OUT=out/study
mkdir -p "$OUT"
grep -v '^#' scripts/trials.txt | grep . | sed "s#DATA#$DATA#g" >"$OUT/trials.txt"
for kind in "${KINDS[@]}"; do
  build/release/kin2grf study "$kind" --trial-list "$OUT/trials.txt" --json "$OUT/$kind.json" \
    --report "$OUT/$kind.html" | tee "$OUT/$kind.txt"
done
