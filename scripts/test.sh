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
# The readers, outputs, filters, solver and parallel tests under ASan/UBSan, built with the
# library the fuzzers use (one sanitizer build of it serves both; line tables only, which keep the
# sanitizers' stack traces at a fraction of full debug information's compile time), then the fuzz
# targets, 10 s each, seeded with the project's own files; scripts/fuzz.sh 600 is the long run.
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target kin2grf_tests
ctest --preset fuzz -j2 -R 'C3d|Trc|Sto|Corrupt|Fuzz|Solver|NoisyMarkers|SyntheticWalk|Parallel|Text|OutputFile|InputFile'
bash scripts/fuzz.sh 10
