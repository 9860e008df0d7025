#!/usr/bin/env bash
# The solver scaling benchmark (issue 3): builds Release and writes
# out/scaling/scaling.csv and scaling.png, printing the table.
#   scripts/scaling.sh [--max-subdivisions 6]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
/usr/bin/python3 experiments/scaling/run.py build-release out/scaling "$@"
