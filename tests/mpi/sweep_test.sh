#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Sweeps over MPI ranks against the same sweeps in one process (ctest runs
# each case; tests/CMakeLists.txt). Usage:
#   sweep_test.sh CASE MPIEXEC FIBERFLUID SOURCE_DIR
# CASE: same-bits | failed-variant | interrupted
set -uo pipefail
case_name="$1" mpiexec="$2" fiberfluid="$3" source="$4"
here="$source/tests/mpi"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# As CI runs: as root, two ranks on however many cores there are. One thread
# per variant everywhere, so that both sides run each variant alike.
mpirun=("$mpiexec" --allow-run-as-root --oversubscribe)
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive

fail() {
  echo "FAIL: $*"
  exit 1
}

# The ranks (1-based columns of comparison.csv named "rank") of a folder's runs.
ranks_of() {
  python3 - "$1/comparison.csv" <<'EOF'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
print(" ".join(sorted({r["rank"] for r in rows})))
EOF
}

case "$case_name" in
same-bits)
  # The liver sweep: in one process (two variants at a time), under one rank
  # and under two; the same bits all three ways.
  sweep="$source/experiments/liver_sweep.json"
  "$fiberfluid" run "$sweep" -q -j 2 -o "$work/serial" >/dev/null || fail "the serial run"
  "${mpirun[@]}" -np 1 "$fiberfluid" run "$sweep" -q -o "$work/one" >/dev/null || fail "one rank"
  "${mpirun[@]}" -np 2 "$fiberfluid" run "$sweep" -q -o "$work/two" >/dev/null || fail "two ranks"
  python3 "$here/same_outputs.py" "$work/serial" "$work/one" || fail "one rank differs"
  python3 "$here/same_outputs.py" "$work/serial" "$work/two" || fail "two ranks differ"
  [ "$(ranks_of "$work/one")" = "0" ] || fail "one rank: ranks $(ranks_of "$work/one")"
  # Four variants dealt to two ranks that both ask: each ran some.
  [ "$(ranks_of "$work/two")" = "0 1" ] || fail "two ranks: ranks $(ranks_of "$work/two")"
  # Nothing but the output folder is left beside it (no staging folders).
  [ "$(ls "$work" | tr '\n' ' ')" = "one serial two " ] || fail "left: $(ls "$work")"
  ;;
failed-variant)
  # A variant that fails does not stop the others; the folder is DIR.failed,
  # the same as the serial run's, exit status 2. (FAILED names the folder:
  # both are called out, in folders of their own.)
  sweep="$here/failing_sweep.json"
  mkdir "$work/serial" "$work/two"
  "$fiberfluid" run "$sweep" -q -j 2 -o "$work/serial/out" >/dev/null 2>&1
  status=$?
  [ $status -eq 2 ] || fail "the serial run: status $status"
  "${mpirun[@]}" -np 2 "$fiberfluid" run "$sweep" -q -o "$work/two/out" >/dev/null 2>"$work/err"
  status=$?
  [ $status -eq 2 ] || fail "two ranks: status $status"
  grep -q "runaway" "$work/err" || fail "two ranks did not say why: $(cat "$work/err")"
  [ "$(ls "$work/two")" = "out.failed" ] || fail "two ranks left: $(ls "$work/two")"
  python3 "$here/same_outputs.py" "$work/serial/out.failed" "$work/two/out.failed" ||
    fail "they differ"
  for v in soft stiff; do
    [ -f "$work/two/out.failed/$v/final.obj" ] || fail "variant $v did not run to its end"
  done
  ;;
interrupted)
  # Ctrl-C reaches every rank (here SIGINT to each, as a terminal sends it to
  # the foreground processes): every rank stops at its next check, the
  # status is 130, and nothing is left of the output folder.
  sweep="$here/sphere_newton_sweep.json"
  "${mpirun[@]}" -np 2 "$fiberfluid" run "$sweep" -q -o "$work/out" >/dev/null 2>"$work/err" &
  launcher=$!
  for _ in $(seq 1 100); do  # until both ranks run (up to 10 s)
    [ "$(pgrep -f -c -- "run $sweep -q -o $work/out")" -ge 3 ] && break
    sleep 0.1
  done
  sleep 1
  pkill -INT -f -- "^$fiberfluid run $sweep" || fail "no rank to interrupt"
  start=$(date +%s)
  wait $launcher
  status=$?
  took=$(($(date +%s) - start))
  [ $status -eq 130 ] || fail "status $status (expected 130): $(cat "$work/err")"
  [ $took -le 20 ] || fail "the ranks took $took s to stop"
  grep -q "interrupted" "$work/err" || fail "rank 0 did not say it was interrupted: $(cat "$work/err")"
  [ "$(ls -A "$work" | tr '\n' ' ')" = "err " ] || fail "left behind: $(ls -A "$work")"
  ;;
*)
  fail "unknown case $case_name"
  ;;
esac
echo "ok: $case_name"
