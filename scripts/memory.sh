#!/usr/bin/env bash
# Peak memory of `kin2grf estimate` against the input file's size, on a generated long trial
# (issue 10's target: at most twice the file's size plus a constant). Uses the release build.
#   bash scripts/memory.sh [SECONDS]      (default 600: 60,000 frames of the synthetic walk)
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_LONG=${1:-600}
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
K=build/release/kin2grf
"$K" make-example --out-dir "$WORK" --seconds "$SECONDS_LONG" >/dev/null
for f in example_walk.c3d example_walk.trc; do
  size=$(stat -c %s "$WORK/$f")
  /usr/bin/time -o "$WORK/peak" -f "%M" "$K" estimate "$WORK/$f" --mass 70 >/dev/null 2>&1
  /usr/bin/time -o "$WORK/base" -f "%M" "$K" --version >/dev/null
  peak_kb=$(tail -1 "$WORK/peak")
  base_kb=$(tail -1 "$WORK/base")
  awk -v f="$f" -v s="$size" -v p="$peak_kb" -v b="$base_kb" 'BEGIN {
    printf "%-18s file %7.1f MB  peak %7.1f MB (process alone %4.1f MB)  peak / file %5.1f\n", f, s / 1e6, p * 1024 / 1e6, b * 1024 / 1e6, p * 1024 / s }'
done
