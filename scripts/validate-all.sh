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

# activity|name|trial and its options (masses: see each data folder's README)
TRIALS=(
  "walking|walking2|$DATA/opensim_c3d_overground_walk/walking2.c3d --mass 64.9"
  "walking|walking5|$DATA/opensim_c3d_overground_walk/walking5.c3d --mass 67.5"
  "walking|rajagopal-walk|$DATA/rajagopal2016_overground_walk/markers_walk.trc --plates $DATA/rajagopal2016_overground_walk/grf_walk.mot --mass 77.3"
  "walking|opencap-walking1|$DATA/opencap_dropjump_walk/walking1_markers.trc --plates $DATA/opencap_dropjump_walk/walking1_grf.mot --mass 68.4"
  "walking|subject01-treadmill|$DATA/opensim_subject01_treadmill_walk/subject01_walk1.trc --static $DATA/opensim_subject01_treadmill_walk/subject01_static.trc --plates $DATA/opensim_subject01_treadmill_walk/subject01_walk1_grf.mot --mass 72.6"
  "walking|pig-flatfoot-full|$DATA/btk_plugingait_walk/PiG_Motion-FlatFoot-Full.c3d"
  "walking|pig-motion3|$DATA/btk_plugingait_walk/PiG_Motion3_FF.c3d"
  "running|rajagopal-run-treadmill|$DATA/rajagopal2016_treadmill_run/motion_capture_run.trc --static $DATA/rajagopal2016_treadmill_run/static_run.trc --plates $DATA/rajagopal2016_treadmill_run/grf_run.mot --mass 72.84"
  "jump landing|opencap-dropjump|$DATA/opencap_dropjump_walk/DJ1_markers.trc --plates $DATA/opencap_dropjump_walk/DJ1_grf.mot --mass 68.4"
)
for row in "${TRIALS[@]}"; do
  IFS='|' read -r activity name args <<<"$row"
  for config in defaults paper; do
    extra=""
    [ "$config" = paper ] && extra="--paper"
    # shellcheck disable=SC2086
    if ! $BIN validate $args $extra --json "$OUT/$name.$config.json" >"$OUT/$name.$config.txt" 2>"$OUT/$name.$config.log"; then
      echo "validate-all: $name ($config) failed:" >&2; cat "$OUT/$name.$config.log" >&2; exit 1
    fi
  done
  echo "$activity|$name|$args" >>"$OUT/trials.txt"
  echo "validated $name"
done
/usr/bin/python3 scripts/validation_table.py "$OUT" "$DATA" "$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src include data || echo '+local changes')" >docs/VALIDATION.md
echo "wrote docs/VALIDATION.md"
