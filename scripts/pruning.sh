#!/usr/bin/env bash
# The pruning benchmark (issue 4): builds Release and prints the time to
# prune the shared concave meshes and a 5,000-vertex torus.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
build-release/experiments/pruning/fiberfluid_pruning "$@"
