#!/usr/bin/env bash
# Build with warnings as errors and run the whole test suite, then the reader, output, corrupt-file
# and solver tests again under AddressSanitizer/UBSan, and the parser fuzzers briefly. This is the
# README's test command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset ci >/dev/null
cmake --build --preset ci
ctest --preset ci -j2
# The readers, outputs, filters, solver, stance parameters and parallel tests under ASan/UBSan, built with the
# library the fuzzers use (one sanitizer build of it serves both; line tables only, which keep the
# sanitizers' stack traces at a fraction of full debug information's compile time), then the fuzz
# targets, briefly, seeded with the project's own files; scripts/fuzz.sh 600 is the long run.
# The test subset and the fuzz targets are built in one call, so that both cores stay busy to the
# end (scripts/fuzz.sh then finds them built). The fuzzers run 5 s each here: a smoke run of the
# parsers under the sanitizers; the search for bugs is scripts/fuzz.sh's own, for minutes.
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target kin2grf_tests fuzz_c3d fuzz_trc fuzz_sto fuzz_mapping fuzz_cop_function fuzz_trial_list
ctest --preset fuzz -j2 -R 'C3d|Trc|Sto|Corrupt|Fuzz|Solver|NoisyMarkers|SyntheticWalk|Parallel|Text|OutputFile|InputFile|StanceParameters'
bash scripts/fuzz.sh 5
