#!/usr/bin/env bash
# Threads on a shared machine (issue 42): builds Release and runs
# experiments/threads_benchmark.py (the soft cantilever alone and beside a busy
# process: the default wait, libgomp's spinning and one thread; about two minutes).
#   scripts/threads_benchmark.sh [--repeats 15] [--phantom]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
/usr/bin/python3 experiments/threads_benchmark.py build-release/src/app/fiberfluid "$@"
