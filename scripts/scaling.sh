#!/usr/bin/env bash
# The solver scaling benchmark (issue 3): builds Release and writes
# out/scaling/scaling.csv and scaling.png, printing the table.
#   scripts/scaling.sh [--max-subdivisions 6]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DFIBERFLUID_BUILD_TESTS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
cmake --build build-release -j"$(nproc)"
/usr/bin/python3 experiments/scaling/run.py build-release out/scaling "$@"
