#!/usr/bin/env bash
# The calibration benchmark (issue 9): Y0, beta and gamma of the bunny (1,366
# vertices, 10 Newton steps) from a start a factor 3 away, with the analytic
# Jacobian and with central differences in one run; first under gravity alone,
# then between paddles. Builds Release and prints the tables (about 12 minutes;
# --skip-differences: the analytic fits only, about 2).
#   scripts/fit_benchmark.sh [--skip-differences]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
bench=build-release/experiments/fit_benchmark/fiberfluid_fit_benchmark
for experiment in bunny_gravity_truth bunny_truth; do
  "$bench" "experiments/fit_benchmark/$experiment.json" "$@"
done
