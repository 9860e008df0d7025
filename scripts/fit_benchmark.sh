#!/usr/bin/env bash
# The calibration benchmark (issue 9): Y0, beta and gamma of the bunny (1,366
# vertices, 10 Newton steps) from a start a factor 3 away, with the analytic
# Jacobian and with central differences in one run; first under gravity alone,
# then between paddles (analytic only unless --differences: contact makes each
# forward run several times longer). Builds Release and prints the tables.
#   scripts/fit_benchmark.sh [--differences]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
bench=build-release/experiments/fit_benchmark/fiberfluid_fit_benchmark
"$bench" experiments/fit_benchmark/bunny_gravity_truth.json
if [[ "${1:-}" == "--differences" ]]; then
  "$bench" experiments/fit_benchmark/bunny_truth.json
else
  "$bench" experiments/fit_benchmark/bunny_truth.json --skip-differences
fi
