#!/usr/bin/env bash
# Peak memory of `kin2grf estimate` against the input file's size, on a generated long trial
# (issue 10's target: at most twice the file's size plus a constant). Uses the release build.
#   bash scripts/memory.sh [SECONDS] [DATA_DIR] [CAPTURE_SECONDS]
# Three kinds of input:
#  - the synthetic walk at 100 Hz, C3D (14 markers, 12 analog channels at the marker rate) and TRC,
#    SECONDS long (default 600: 60,000 frames) and half as long: as small a file per frame as a
#    trial can be; the two lengths give the peak's growth per byte of file;
#  - the same walk as a long capture is recorded, 2 kHz markers and 10 kHz analog (issue 10's
#    example), CAPTURE_SECONDS long (default 120; 600 s is a 557 MB file, and make-example takes
#    4 GB and 40 s to write it);
#  - where DATA_DIR (../shared/data) is, four lab C3D files with their scripts/trials.txt options.
# Each run writes the outputs a user asks for (-o GRF.mot, --csv, --json), as their writing is part
# of the peak. KIN2GRF=path/to/kin2grf measures another build (the release build by default).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_LONG=${1:-600}
DATA=${2:-../shared/data}
CAPTURE_SECONDS=${3:-120}
# The release build writes the inputs (make-example); KIN2GRF, if given, is the build measured.
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
K=${KIN2GRF:-build/release/kin2grf}
OUTS=(-o "$WORK/out.mot" --csv "$WORK/out.csv" --json "$WORK/out.json")
GEN=build/release/kin2grf
measure() {  # FILE LABEL: estimate's peak against the file's size; sets SIZE and PEAK (bytes)
  local base_kb
  SIZE=$(stat -c %s "$1")
  /usr/bin/time -o "$WORK/peak" -f "%M" "$K" estimate "$1" --mass 70 "${OUTS[@]}" >/dev/null 2>&1
  /usr/bin/time -o "$WORK/base" -f "%M" "$K" --version >/dev/null
  PEAK=$(( $(tail -1 "$WORK/peak") * 1024 ))
  base_kb=$(tail -1 "$WORK/base")
  awk -v f="$2" -v s="$SIZE" -v p="$PEAK" -v b="$base_kb" 'BEGIN {
    printf "%-34s file %7.1f MB  peak %7.1f MB (process alone %4.1f MB)  peak / file %5.2f\n", f, s / 1e6, p / 1e6, b * 1024 / 1e6, p / s }'
}
# The walk at half the length too: what a second of trial adds to the peak against what it adds to
# the file (the target's "twice the file" is this slope; the constant is the rest).
HALF=$(( SECONDS_LONG / 2 ))
"$GEN" make-example --out-dir "$WORK/half" --seconds "$HALF" >/dev/null
"$GEN" make-example --out-dir "$WORK/lean" --seconds "$SECONDS_LONG" >/dev/null
for ext in c3d trc; do
  measure "$WORK/half/example_walk.$ext" "walk ${HALF} s, 100 Hz, ${ext^^}"
  s0=$SIZE p0=$PEAK
  measure "$WORK/lean/example_walk.$ext" "walk ${SECONDS_LONG} s, 100 Hz, ${ext^^}"
  awk -v s0="$s0" -v p0="$p0" -v s1="$SIZE" -v p1="$PEAK" -v e="${ext^^}" 'BEGIN {
    printf "  %s from %.1f to %.1f MB of file: %.2f bytes of peak per byte of file; peak - 2 x file %.1f MB\n", e, s0 / 1e6, s1 / 1e6,
      (p1 - p0) / (s1 - s0), (p1 - 2 * s1) / 1e6 }'
done
rm -rf "$WORK/half"
rm -rf "$WORK/lean"
# The same walk with 2 mm of marker noise: the noise rule lowers its kinematic cut-off, and the
# stance floor (min_kinematic_cycles) solves it twice, keeping its unfiltered coordinates between.
"$GEN" make-example --out-dir "$WORK/noisy" --seconds "$SECONDS_LONG" --marker-noise 2 >/dev/null
measure "$WORK/noisy/example_walk.c3d" "walk ${SECONDS_LONG} s, 2 mm noise, C3D"
awk -v s="$SIZE" -v p="$PEAK" 'BEGIN { printf "  peak - 2 x file %.1f MB\n", (p - 2 * s) / 1e6 }'
rm -rf "$WORK/noisy"
"$GEN" make-example --out-dir "$WORK/capture" --seconds "$CAPTURE_SECONDS" --rate 2000 --analog-rate 10000 >/dev/null
measure "$WORK/capture/example_walk.c3d" "walk ${CAPTURE_SECONDS} s, 2 kHz + 10 kHz analog"
rm -rf "$WORK/capture"
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
