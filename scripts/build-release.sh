#!/usr/bin/env bash
# Installs what the build needs and builds fiberfluid in Release (build-release/),
# without the tests: what run.sh, fit.sh and the benchmarks start with.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DFIBERFLUID_BUILD_TESTS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
cmake --build build-release -j"$(nproc)"
