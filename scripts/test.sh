#!/usr/bin/env bash
# Build with warnings as errors and run the whole test suite, then the reader, corrupt-file and
# solver tests again under AddressSanitizer/UBSan, and the parser fuzzers briefly. This is the README's test
# command and what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset ci >/dev/null
cmake --build --preset ci
ctest --preset ci -j2
cmake --preset asan >/dev/null
cmake --build --preset asan --target kin2grf_tests
ctest --preset asan -j2 -R 'C3d|Trc|Sto|Corrupt|Fuzz|Solver|NoisyMarkers|SyntheticWalk|Parallel|Text'
# The parsers under libFuzzer with the library instrumented (ASan/UBSan), 20 s each, seeded with
# the project's own files; scripts/fuzz.sh 600 is the long run.
bash scripts/fuzz.sh 20
