#!/usr/bin/env bash
# Peak memory of `kin2grf estimate` against the input file's size, on a generated long trial
# (issue 10's target: at most twice the file's size plus a constant). Uses the release build.
#   bash scripts/memory.sh [SECONDS] [DATA_DIR]   (default 600: 60,000 frames of the synthetic walk;
#   then, where DATA_DIR (../shared/data) is, four lab C3D files with their scripts/trials.txt options)
# Each run writes the outputs a user asks for (-o GRF.mot, --csv, --json), as their writing is part
# of the peak. KIN2GRF=path/to/kin2grf measures another build (the release build by default).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_LONG=${1:-600}
DATA=${2:-../shared/data}
if [ -z "${KIN2GRF:-}" ]; then
  cmake --preset release >/dev/null
  cmake --build --preset release >/dev/null
fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
K=${KIN2GRF:-build/release/kin2grf}
OUTS=(-o "$WORK/out.mot" --csv "$WORK/out.csv" --json "$WORK/out.json")
"$K" make-example --out-dir "$WORK" --seconds "$SECONDS_LONG" >/dev/null
for f in example_walk.c3d example_walk.trc; do
  size=$(stat -c %s "$WORK/$f")
  /usr/bin/time -o "$WORK/peak" -f "%M" "$K" estimate "$WORK/$f" --mass 70 "${OUTS[@]}" >/dev/null 2>&1
  /usr/bin/time -o "$WORK/base" -f "%M" "$K" --version >/dev/null
  peak_kb=$(tail -1 "$WORK/peak")
  base_kb=$(tail -1 "$WORK/base")
  awk -v f="$f" -v s="$size" -v p="$peak_kb" -v b="$base_kb" 'BEGIN {
    printf "%-18s file %7.1f MB  peak %7.1f MB (process alone %4.1f MB)  peak / file %5.1f\n", f, s / 1e6, p * 1024 / 1e6, b * 1024 / 1e6, p * 1024 / s }'
done
# Lab files: markers with 1-2 kHz plates, as `estimate` reads them (the plates without samples).
[ -d "$DATA" ] || exit 0
for f in opensim_c3d_overground_walk/walking2.c3d btk_plugingait_walk/PiG_Motion-FlatFoot-Full.c3d \
         uwa_control1_fast_walk/Fast_Walking.c3d ufabc_rbds001_treadmill_run/RBDS001runT35.c3d; do
  [ -f "$DATA/$f" ] || continue
  args=$(grep -v '^#' scripts/trials.txt | grep -F "DATA/$f" | head -1 | cut -d'|' -f4- | sed "s#DATA#$DATA#g")
  [ -n "$args" ] || args="$DATA/$f"
  size=$(stat -c %s "$DATA/$f")
  # shellcheck disable=SC2086
  /usr/bin/time -o "$WORK/peak" -f "%M" "$K" estimate $args "${OUTS[@]}" >/dev/null 2>&1
  peak_kb=$(tail -1 "$WORK/peak")
  awk -v f="$(basename "$f")" -v s="$size" -v p="$peak_kb" 'BEGIN {
    printf "%-28s file %5.2f MB  peak %6.1f MB  peak / file %5.1f\n", f, s / 1e6, p * 1024 / 1e6, p * 1024 / s }'
done
