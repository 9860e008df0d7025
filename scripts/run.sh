#!/usr/bin/env bash
# Builds fiberfluid (Release) and runs an experiment: by default the paper's
# sphere, with its outputs and a plot in out/<name>/.
#   scripts/run.sh [experiments/NAME.json]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh

experiment="${1:-experiments/sphere.json}"
name="$(basename "$experiment" .json)"
build-release/src/app/fiberfluid run "$experiment" -o "out/$name" --check --plot
if [[ -f "out/$name/series.pvd" ]]; then
  echo "plot: out/$name/plot.png; open out/$name/series.pvd in ParaView"
else  # a sweep: one series per variant
  echo "plot: out/$name/plot.png; open out/$name/<variant>/series.pvd in ParaView"
fi
