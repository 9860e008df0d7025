#!/usr/bin/env bash
# Builds fiberfluid (Release), runs the accuracy benchmarks of Alterovitz and
# Goldberg (the block and needle with MP1 and MP2, the bending rod; each with
# the fiber model) and draws their plots: out/<name>/benchmark.png.
#   scripts/benchmarks.sh [experiments/benchmark_NAME.json ...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh

if [ "$#" -eq 0 ]; then
  set -- experiments/benchmark_block_mp1.json experiments/benchmark_block_mp2.json \
         experiments/benchmark_rod.json
fi
for experiment in "$@"; do
  name="$(basename "$experiment" .json)"
  build-release/src/app/fiberfluid run "$experiment" -o "out/$name" --check
  /usr/bin/python3 experiments/plot_benchmark.py "out/$name"
done
