#!/usr/bin/env bash
# README's first command: install what is needed, build, and run the main job on the bundled
# examples: kin2grf's synthetic walk and squat (make-example), then a recorded overground walk
# (data/example/walking2.c3d, OpenSim's test capture, Apache-2.0), estimated, validated against
# its own force plate with the HTML report and exported for OpenSim. The recorded walk comes last
# so that its validation table is what the terminal ends with.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release
k=./build/release/kin2grf
echo "== kin2grf's synthetic example (make-example)"
$k make-example --out-dir out/example
$k info out/example/example_walk.c3d
$k estimate out/example/example_walk.c3d -o out/example/estimated_grf.mot \
  --csv out/example/estimated.csv --json out/example/estimated.json --opensim out/example/opensim
echo
rec=out/recorded-walk
mkdir -p "$rec"
echo "== A recorded walk (data/example/walking2.c3d; its source and licence: data/example/README.md)"
$k estimate data/example/walking2.c3d --mass 64.9 -o "$rec/estimated_grf.mot" --csv "$rec/estimated.csv" \
  --json "$rec/estimated.json" --events "$rec/gait_events.csv" --report "$rec/estimate.html" --opensim "$rec/opensim" \
  --c3d "$rec/estimated.c3d" --stances "$rec/stances.csv" --stance-curves "$rec/stance_curves.csv"
$k validate data/example/walking2.c3d --mass 64.9 --json "$rec/validation.json" --report "$rec/validation.html" \
  --stance-curves "$rec/validation_stance_curves.csv"
echo
echo "Outputs in out/example/: the synthetic walk (example_walk.c3d, .trc, _grf.mot), a squat, and the walk's"
echo "  estimate (estimated_grf.mot, estimated.csv, estimated.json, opensim/). Its plates are synthetic (the"
echo "  model's own totals shared between the feet by a fixed rule), so the demo does not score against them."
echo "Outputs in out/recorded-walk/: the recorded walk's estimate (estimated_grf.mot in OpenSim's frame,"
echo "  estimated.csv, estimated.json, gait_events.csv, estimate.html: its plots without plates; stances.csv,"
echo "  each stance's parameters; stance_curves.csv, each stance at 0-100 % of it), its validation against the"
echo "  walk's own force plate above (validation.html, validation.json, validation_stance_curves.csv), and opensim/"
echo "  (GRF .mot, markers .trc and ExternalLoads .xml for OpenSim's inverse dynamics), and estimated.c3d"
echo "  (the markers with the estimate as force platforms 1 right and 2 left, for Nexus, Visual3D or ezc3d)."
echo "docs/VALIDATION.md has the accuracy on 16 recorded trials from 8 labs."
