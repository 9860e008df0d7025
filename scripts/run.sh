#!/usr/bin/env bash
# Builds fiberfluid (Release) and runs an experiment: by default the paper's
# sphere, with its outputs and a plot in out/<name>/.
#   scripts/run.sh [experiments/NAME.json]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DFIBERFLUID_BUILD_TESTS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
cmake --build build-release -j"$(nproc)"

experiment="${1:-experiments/sphere.json}"
name="$(basename "$experiment" .json)"
build-release/src/app/fiberfluid run "$experiment" -o "out/$name" --check
/usr/bin/python3 experiments/plot.py "out/$name/summary.json" "out/$name/plot.png"
if [[ -f "out/$name/series.pvd" ]]; then
  echo "plot: out/$name/plot.png; open out/$name/series.pvd in ParaView"
else  # a sweep: one series per variant
  echo "plot: out/$name/plot.png; open out/$name/<variant>/series.pvd in ParaView"
fi
