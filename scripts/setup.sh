#!/usr/bin/env bash
# Install what kin2grf needs from Debian's packages (and nothing from anywhere else).
# Safe to run again: it skips apt when every package is already installed.
set -euo pipefail
packages=(cmake ninja-build make g++ clang libclang-rt-14-dev libeigen3-dev libcli11-dev nlohmann-json3-dev
          libgtest-dev libgmock-dev libbenchmark-dev
          libjs-chart.js chromium python3 time
          pybind11-dev python3-dev python3-numpy python3-pandas python3-pytest python3-distributed)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
echo "setup: all packages present"
# The presets build with Ninja (its finer dependencies keep both cores busy across the libraries'
# boundaries: the test command's fresh build 11.6 -> 10.5 min). A preset's folder configured by
# another generator would make `cmake --preset` fail, so such a folder is cleared here (build
# output only; folders of other names are left alone).
root="$(cd "$(dirname "$0")/.." && pwd)"
for preset in dev release ci asan fuzz; do
  cache="$root/build/$preset/CMakeCache.txt"
  [ -f "$cache" ] || continue
  if ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$cache"; then
    echo "setup: $(dirname "$cache") was configured by another generator; clearing it for the presets' Ninja"
    rm -rf "$(dirname "$cache")"
  fi
done
