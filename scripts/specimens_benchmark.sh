#!/usr/bin/env bash
# Real specimens (issue 42): builds Release and runs experiments/specimens_benchmark.py
# (the compressed cylinder and the bending phantom, alone and beside a busy
# process: about 3 minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
/usr/bin/python3 experiments/specimens_benchmark.py build-release/src/app/fiberfluid --busy "$@"
