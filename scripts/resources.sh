#!/usr/bin/env bash
# The resource estimate against measured time and memory (issue 11): builds
# Release and runs experiments/resources.py (about 5 minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
/usr/bin/python3 experiments/resources.py build-release out/resources
