#!/usr/bin/env bash
# README's first command: install what is needed, build, and run the main job on the bundled
# examples: a recorded overground walk (data/example/walking2.c3d, OpenSim's test capture,
# Apache-2.0), estimated and validated against its own force plates with the HTML report and
# exported for OpenSim; then kin2grf's synthetic walk and squat (make-example).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
k=./build/release/kin2grf
rec=out/recorded-walk
mkdir -p "$rec"
echo "== A recorded walk (data/example/walking2.c3d; its source and licence: data/example/README.md)"
$k estimate data/example/walking2.c3d --mass 64.9 -o "$rec/estimated_grf.mot" --csv "$rec/estimated.csv" \
  --json "$rec/estimated.json" --events "$rec/gait_events.csv" --report "$rec/estimate.html" --opensim "$rec/opensim"
$k validate data/example/walking2.c3d --mass 64.9 --json "$rec/validation.json" --report "$rec/validation.html"
echo
echo "== kin2grf's synthetic example (make-example)"
$k make-example --out-dir out/example
$k info out/example/example_walk.c3d
$k estimate out/example/example_walk.c3d -o out/example/estimated_grf.mot \
  --csv out/example/estimated.csv --json out/example/estimated.json --opensim out/example/opensim
echo
echo "Outputs in out/recorded-walk/: the recorded walk's estimate (estimated_grf.mot, estimated.csv,"
echo "  estimated.json, gait_events.csv, estimate.html: its plots without plates), its validation against the walk's own force plate (validation.html, validation.json)"
echo "  and opensim/ (GRF .mot, markers .trc and ExternalLoads .xml for OpenSim's inverse dynamics)."
echo "Outputs in out/example/: the synthetic walk (example_walk.c3d, .trc, _grf.mot), a squat, and the walk's"
echo "  estimate (estimated_grf.mot, estimated.csv, estimated.json, opensim/). Its plates are synthetic (the model's"
echo "  own totals shared between the feet by a fixed rule), so the demo does not score against them:"
echo "  docs/VALIDATION.md has the accuracy on 14 recorded trials from 8 labs."
