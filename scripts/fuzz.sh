#!/usr/bin/env bash
# Build the libFuzzer targets with clang, the library itself under ASan/UBSan (the `fuzz`
# preset), and run each target (C3D, TRC, STO, mapping files, COP-function files, trial lists),
# two at a time, for SECONDS each (default 30) under -rss_limit_mb=2048, seeded
# with a corpus the project makes itself (files written by kin2grf's writers and the damaged files
# of tests/corpus; no shared data).
# Exits non-zero on any crash, leak, timeout or out-of-memory; a reproducer is left in build/fuzz.
#   bash scripts/fuzz.sh [SECONDS]        (CI runs it for a short time; 600 for the long run)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
bash scripts/setup.sh >/dev/null
cmake --preset fuzz >/dev/null
# The fuzz targets alone (not the command line, which the corpus is made with from an ordinary build).
cmake --build --preset fuzz --target fuzz_c3d fuzz_trc fuzz_sto fuzz_mapping fuzz_cop_function fuzz_trial_list
# The seed corpus is written by the CLI of an ordinary build (the ci one when it exists).
cli=build/ci/kin2grf
if [ ! -x "$cli" ]; then
  cmake --preset dev >/dev/null
  cmake --build --preset dev --target kin2grf_cli
  cli=build/dev/kin2grf
fi
corpus=build/fuzz/corpus
targets="c3d trc sto mapping cop_function trial_list"
for t in $targets; do mkdir -p "$corpus/$t"; done
"$cli" make-example --seconds 1 --out-dir "$corpus/seed" >/dev/null
cp "$corpus"/seed/*.c3d "$corpus/c3d/"
cp "$corpus"/seed/*.trc "$corpus/trc/"
cp "$corpus"/seed/*.mot "$corpus/sto/"
# and the committed corpus of damaged files (tests/corpus, from scripts/make_corpus.py)
cp tests/corpus/*.c3d "$corpus/c3d/"
cp tests/corpus/*.trc "$corpus/trc/"
cp tests/corpus/*.mot "$corpus/sto/"
# The JSON and list inputs: the presets (mapping files), the fitted COP functions and the damaged
# one, and the development trial list.
cp data/presets/*.json "$corpus/mapping/"
cp data/cop-function/*.json tests/corpus/cop_*.json "$corpus/cop_function/"
cp scripts/trials.txt "$corpus/trial_list/"
printf 'walking|lab|a|a.c3d --mass 70 --plates p.mot\r\nrunning|b|c.trc --paper\n' >"$corpus/trial_list/small.txt"

# Two targets at a time (one per core of the 2-core machines this runs on).
run_target() {
  local t=$1
  if ! (cd build/fuzz && ./fuzz/fuzz_$t -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
          -print_final_stats=1 "corpus/$t" >"fuzz_$t.log" 2>&1); then
    echo "fuzz_$t FAILED:"; tail -40 "build/fuzz/fuzz_$t.log"; return 1
  fi
  echo "fuzz_$t: ${seconds} s, $(grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "build/fuzz/fuzz_$t.log" | tr '\n' ' ')"
}
status=0
set -- $targets
while [ $# -gt 0 ]; do
  run_target "$1" & first=$!
  second=""
  if [ $# -gt 1 ]; then run_target "$2" & second=$!; fi
  wait "$first" || status=1
  if [ -n "$second" ]; then wait "$second" || status=1; fi
  shift; [ $# -gt 0 ] && shift
done
exit $status
