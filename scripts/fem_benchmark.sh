#!/usr/bin/env bash
# The accuracy benchmarks' performance (issue 10): seconds per simulated second
# for each solver on each scene (default and 4x finer meshes, CHOLMOD and
# Gauss-Seidel), the fiber model on the same scenes, and Mesh_3's time for the
# liver and the bunny. Builds Release and prints markdown tables.
#   scripts/fem_benchmark.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
/usr/bin/python3 experiments/fem_benchmark.py build-release
