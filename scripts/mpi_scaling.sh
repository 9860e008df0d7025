#!/usr/bin/env bash
# The MPI scaling table (issue 26, docs/parallel.md): each workload under 1
# and 2 ranks (mpirun) with 1 and 2 OpenMP threads per rank, its wall time
# and efficiency against one rank with the same threads, and that the
# results are the same bits whatever the ranks. Builds Release first.
#   scripts/mpi_scaling.sh [--repeats N]   (best of N runs each; default 1)
# Workloads: the liver sweep (4 variants, linear), a Newton sweep on the
# 2,562-vertex sphere (6 variants, tests/mpi), the multi-start fit of the
# synthetic liver (8 starts), the two-liver calibration (2 specimens).
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=1
[ "${1:-}" = "--repeats" ] && repeats="$2"
[ "${SKIP_BUILD:-0}" = 1 ] || scripts/build-release.sh
fiberfluid="$PWD/build-release/src/app/fiberfluid"
"$fiberfluid" --version | grep -q "mpi: none" && {
  echo "this build has no MPI (scripts/install-deps.sh installs Open MPI; rebuild)" >&2
  exit 1
}
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cores=$(nproc)

workloads=(
  "liver sweep|run|experiments/liver_sweep.json"
  "sphere Newton sweep|run|tests/mpi/sphere_newton_sweep.json"
  "multi-start fit|fit|experiments/fit_synthetic_liver_multistart.json"
  "two-liver calibration|fit|experiments/calibrate_two_livers.json"
)

# Wall time of one run (s), best of $repeats; its output kept in $work/$3.
# One item at a time per rank (-j 1: one rank runs one variant at a time,
# as every rank does under mpirun), with $threads OpenMP threads each.
timed() {
  local ranks="$1" threads="$2" out="$3" command="$4" file="$5" best=""
  local jobs=()
  [ "$command" = run ] && jobs=(-j 1)
  for _ in $(seq 1 "$repeats"); do
    rm -rf "$work/$out"
    local start end
    start=$(date +%s.%N)
    OMP_NUM_THREADS="$threads" OMP_WAIT_POLICY=passive mpirun --allow-run-as-root \
      --oversubscribe --bind-to none -np "$ranks" "$fiberfluid" "$command" "$file" "${jobs[@]}" -q \
      -o "$work/$out" >/dev/null 2>&1 || { echo "failed: $ranks ranks, $threads threads: $file" >&2; exit 1; }
    end=$(date +%s.%N)
    best=$(python3 -c "t=$end-$start; b='$best'; print(t if not b else min(t, float(b)))")
  done
  echo "$best"
}

echo "machine: $cores cores; $(mpirun --version | head -1); best of $repeats"
echo
echo "| workload | ranks x threads | wall s | speed-up | efficiency | same bits as 1 rank |"
echo "|---|---|---|---|---|---|"
for entry in "${workloads[@]}"; do
  IFS="|" read -r name command file <<<"$entry"
  for threads in 1 2; do
    base=$(timed 1 "$threads" "one_$threads" "$command" "$file")
    printf "| %s | 1 x %d | %.2f | 1.00 | 1.00 | - |\n" "$name" "$threads" "$base"
    t=$(timed 2 "$threads" "two_$threads" "$command" "$file")
    same=$(python3 tests/mpi/same_outputs.py "$work/one_$threads" "$work/two_$threads" >/dev/null && echo yes || echo NO)
    python3 -c "b=$base; t=$t; print('| $name | 2 x $threads | %.2f | %.2f | %.2f | $same |' % (t, b / t, b / t / 2))"
  done
done
