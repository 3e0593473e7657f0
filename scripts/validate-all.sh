#!/usr/bin/env bash
# Run `kin2grf validate` on every development trial with force plates in ../shared/data, with the
# defaults and with the paper's configuration (--paper), and write docs/VALIDATION.md.
#   bash scripts/validate-all.sh [DATA_DIR]
# The JSON of every run is kept in out/validation/ (not committed).
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-../shared/data}
[ -d "$DATA" ] || { echo "validate-all: no data folder $DATA" >&2; exit 1; }
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
BIN=build/release/kin2grf
OUT=out/validation
rm -rf "$OUT" && mkdir -p "$OUT"

# scripts/trials.txt: activity|lab|name|TRIAL [options], DATA standing for the data folder.
mapfile -t TRIALS < <(grep -v '^#' scripts/trials.txt | grep . | sed "s#DATA#$DATA#g")
for row in "${TRIALS[@]}"; do
  IFS='|' read -r activity lab name args <<<"$row"
  # 3d: the 3D model (--model 3d) at its defaults; 3d-lcX: its lateral force's cut-off at X Hz (0:
  # the kinematic cut-off), 3d-load: the split by load alone, 3d-lumped: the arms and head in the
  # torso, 3d-nolag: the torso's lateral share not delayed, 3d-split: a landing's bilateral stance
  # split as everywhere else, 3d-toeX: the COP's medial turn past the MT heads at X m/m, for the
  # leave-one-lab-out choices.
  for config in defaults paper 3d 3d-lc0 3d-lc2 3d-lc3 3d-lc3.5 3d-lc4 3d-lc5 3d-load 3d-lumped 3d-nolag 3d-split \
    3d-toe0 3d-toe0.5 3d-toe0.75 3d-toe1; do
    extra=""
    [ "$config" = paper ] && extra="--paper"
    [ "$config" = 3d ] && extra="--model 3d"
    [[ "$config" == 3d-lc* ]] && extra="--model 3d --lateral-cutoff ${config#3d-lc}"
    [ "$config" = 3d-load ] && extra="--model 3d --lateral-split load"
    [ "$config" = 3d-lumped ] && extra="--model 3d --upper-body lumped"
    [ "$config" = 3d-nolag ] && extra="--model 3d --lateral-lag none"
    [ "$config" = 3d-split ] && extra="--model 3d --lateral-bilateral split"
    [[ "$config" == 3d-toe* ]] && extra="--model 3d --toe-medial-slope ${config#3d-toe}"
    # shellcheck disable=SC2086
    if ! $BIN validate $args $extra --json "$OUT/$name.$config.json" >"$OUT/$name.$config.txt" 2>"$OUT/$name.$config.log"; then
      echo "validate-all: $name ($config) failed:" >&2; cat "$OUT/$name.$config.log" >&2; exit 1
    fi
  done
  echo "$activity|$lab|$name|$args" >>"$OUT/trials.txt"
  echo "validated $name"
done
# Every setting chosen from data, chosen again leave-one-lab-out (in-sample beside held-out).
for kind in speed-gate-ratio r split-distance torso-length torso-lag post-cutoff-cycles double-support-sta min-kinematic-cycles \
  touchdown-fraction touchdown-stop post-cutoff-floor speed-gate-floor speed-gate-standstill running-sway-gain thigh-lag \
  torso-vertical-cutoff double-support-angle still-foot kinematic-edges kinematic-edge-span torque-length; do
  $BIN study "$kind" --trial-list "$OUT/trials.txt" --cross-validate lab --json "$OUT/cv-$kind.json" >"$OUT/cv-$kind.txt" 2>/dev/null
  echo "cross-validated $kind"
done
# The walking COP function: the built-in one beside a refit without each trial's lab.
$BIN fit-cop --trial-list "$OUT/trials.txt" --activity walking --fit-angles --fit-com --leave-one-out -o "$OUT/cv-cop-function.json" \
  >"$OUT/cv-cop-function.txt" 2>/dev/null
echo "cross-validated the COP function"
/usr/bin/python3 scripts/validation_table.py "$OUT" "$DATA" "$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src include data || echo '+local changes')" >"$OUT/VALIDATION.md"
# Written whole or not at all: a failing table script leaves the committed file as it was.
mv "$OUT/VALIDATION.md" docs/VALIDATION.md
echo "wrote docs/VALIDATION.md"
