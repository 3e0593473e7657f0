#!/usr/bin/env bash
# Build the libFuzzer targets with clang and run each for SECONDS (default 30), seeded with a
# corpus the project makes itself (files written by kin2grf's writers; no shared data copied).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
bash scripts/setup.sh
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
cmake --preset dev >/dev/null
cmake --build --preset dev --target kin2grf_cli
corpus=build/fuzz/corpus
mkdir -p "$corpus/c3d" "$corpus/trc" "$corpus/sto"
./build/dev/kin2grf make-example --seconds 0.5 --out-dir "$corpus/seed" >/dev/null
cp "$corpus"/seed/*.c3d "$corpus/c3d/"
cp "$corpus"/seed/*.trc "$corpus/trc/"
cp "$corpus"/seed/*.mot "$corpus/sto/"
for t in c3d trc sto; do
  echo "fuzz_$t: ${seconds} s"
  ./build/fuzz/fuzz/fuzz_$t -max_total_time="$seconds" -max_len=65536 -print_final_stats=1 "$corpus/$t" 2>&1 | tail -4
done
