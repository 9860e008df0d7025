#!/usr/bin/env bash
# Builds fiberfluid (Release) and calibrates an experiment's material to its
# "fit" targets: by default the synthetic liver scan, with fit.json and
# pictures in out/<name>/.
#   scripts/fit.sh [experiments/NAME.json]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh

experiment="${1:-experiments/fit_synthetic_liver.json}"
name="$(basename "$experiment" .json)"
build-release/src/app/fiberfluid fit "$experiment" -o "out/$name" --check
/usr/bin/python3 experiments/plot_fit.py "out/$name"
echo "fit: out/$name/fit.json; open out/$name/fit_target_*.vtu in ParaView"
