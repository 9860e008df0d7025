#!/usr/bin/env bash
# The pruning benchmark (issue 4): builds Release and prints the time to
# prune the shared concave meshes and a 5,000-vertex torus.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DFIBERFLUID_BUILD_TESTS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
cmake --build build-release -j"$(nproc)"
build-release/experiments/pruning/fiberfluid_pruning "$@"
