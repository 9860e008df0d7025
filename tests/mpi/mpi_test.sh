#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs over MPI ranks against the same runs in one process (ctest runs each
# case; tests/CMakeLists.txt). Usage:
#   mpi_test.sh CASE MPIEXEC FIBERFLUID SOURCE_DIR
# CASE: same-bits | failed-variant | interrupted (sweeps) | multistart (a fit) | ranks-disagree
#       | specimens (a calibration over two specimens)
set -uo pipefail
case_name="$1" mpiexec="$2" fiberfluid="$3" source="$4"
here="$source/tests/mpi"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# As CI runs: as root, two ranks on however many cores there are. One thread
# per variant everywhere, so that both sides run each variant alike.
mpirun=("$mpiexec" --allow-run-as-root --oversubscribe)
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
# Under AddressSanitizer (scripts/test.sh's second run): Open MPI leaks by
# design at MPI_Finalize, from components it has unloaded by then (no frames
# to suppress by name). Memory errors and undefined behaviour are still
# fatal here; leaks of this project's code are the one-process tests' to find.
[ -n "${ASAN_OPTIONS:-}" ] && export ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0"

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
  # A signal to one worker rank alone (issue 59, class 4) stops the whole
  # job the same way: its cut-short variant is no failure of its own, so no
  # DIR.failed listing variants as "interrupted".
  "${mpirun[@]}" -np 2 "$fiberfluid" run "$sweep" -q -o "$work/out" >/dev/null 2>"$work/err" &
  launcher=$!
  worker=""
  for _ in $(seq 1 100); do  # until rank 1 runs (up to 10 s)
    for pid in $(pgrep -f -- "^$fiberfluid run $sweep"); do
      tr '\0' '\n' <"/proc/$pid/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1" &&
        worker=$pid
    done
    [ -n "$worker" ] && break
    sleep 0.1
  done
  [ -n "$worker" ] || fail "no rank 1 to interrupt"
  sleep 1
  kill -INT "$worker"
  wait $launcher
  status=$?
  [ $status -eq 130 ] || fail "rank 1 alone: status $status (expected 130): $(cat "$work/err")"
  [ "$(ls -A "$work" | tr '\n' ' ')" = "err " ] || fail "rank 1 alone: left $(ls -A "$work")"
  ;;
multistart)
  # fit_synthetic_liver from 8 starts, dealt over two ranks: the single
  # fit's optimum (its start is the first), reached from other starts too;
  # the same bits as under one rank.
  "$fiberfluid" fit "$source/experiments/fit_synthetic_liver.json" -q -o "$work/single" \
    >/dev/null 2>&1 || fail "the single fit"
  search="$source/experiments/fit_synthetic_liver_multistart.json"
  mkdir "$work/one" "$work/two"
  "${mpirun[@]}" -np 1 "$fiberfluid" fit "$search" -q -o "$work/one/out" >/dev/null 2>&1 ||
    fail "one rank"
  "${mpirun[@]}" -np 2 "$fiberfluid" fit "$search" -q -o "$work/two/out" --check >/dev/null \
    2>"$work/err" || fail "two ranks: $(cat "$work/err")"
  python3 "$here/same_outputs.py" "$work/one/out" "$work/two/out" || fail "two ranks differ"
  python3 - "$work/single/fit.json" "$work/two/out/fit.json" <<'EOF' || fail "the optimum"
import json, sys
single, search = (json.load(open(p)) for p in sys.argv[1:])
found = search["multistart"]
best = found["optima"][0]
fitted = {p["name"]: p["value"] for p in search["parameters"]}
for p in single["parameters"]:
    value, sigma = best["values"][p["name"]], p["standard_error"]
    # The single fit's optimum, to well within its standard error.
    assert abs(value - p["value"]) <= 0.05 * sigma, (p["name"], value, p["value"], sigma)
    assert fitted[p["name"]] == value, "the search's result is not its best optimum"
assert best["starts_reached"] >= 4 and not found["best_found_once"], best
assert sorted({s["rank"] for s in found["starts"]}) == [0, 1], "a rank ran no start"
assert all(s["status"] == "converged" for s in found["starts"]), found["starts"]
print("optimum", best["values"], "from", best["starts_reached"], "of", len(found["starts"]), "starts")
EOF
  ;;
specimens)
  # Two livers, one tissue: the shared Y0 and beta of the truth (20 kPa, 3)
  # within the calibration's 95% intervals, each specimen's gamma (200 N/m)
  # within its own; each rank evaluated a specimen; the same bits as one rank.
  calibration="$source/experiments/calibrate_two_livers.json"
  mkdir "$work/one" "$work/two"
  "${mpirun[@]}" -np 1 "$fiberfluid" fit "$calibration" -q -o "$work/one/out" >/dev/null 2>&1 ||
    fail "one rank"
  "${mpirun[@]}" -np 2 "$fiberfluid" fit "$calibration" -q --check -o "$work/two/out" \
    >/dev/null 2>"$work/err" || fail "two ranks: $(cat "$work/err")"
  python3 "$here/same_outputs.py" "$work/one/out" "$work/two/out" || fail "two ranks differ"
  python3 - "$work/two/out/calibration.json" <<'EOF' || fail "the calibration"
import json, sys
c = json.load(open(sys.argv[1]))
assert c["status"] == "converged", c["status"]
truth = {"Y0": 20000.0, "beta": 3.0, "synthetic.gamma": 200.0, "fine.gamma": 200.0}
for p in c["parameters"]:
    low, high = p["interval_95"]
    assert low <= truth[p["name"]] <= high, (p["name"], low, high)
    assert p["shared"] == (p["name"] in ("Y0", "beta")), p
for s in c["specimens"]:
    share = s["distance"]["standard_deviation"] / s["body_length"]
    assert share < 0.002, (s["name"], share)  # the scans' noise at most
print({p["name"]: p["value"] for p in c["parameters"]})
EOF
  for specimen in synthetic fine; do
    [ -f "$work/two/out/$specimen/fit_target_2.vtu" ] || fail "no fit files for $specimen"
  done
  ;;
ranks-disagree)
  # Issue 43, "ranks agree or stop": mpirun's "A : B" form started the ranks
  # on other experiments; rank 1 computed B's variants under A's record, or
  # (B with fewer variants) the job hung for ever. Now every rank compares a
  # digest of its resolved experiment and surface with rank 0's, and all
  # stop, naming the rank. Also when only the mesh file differs.
  mkdir -p "$work/A" "$work/B" "$work/C" "$work/D"
  python3 "$here/disagree.py" "$work" || fail "making the experiments"
  for other in B C D; do
    timeout 120 "${mpirun[@]}" -np 1 "$fiberfluid" run "$work/A/exp.json" -q -o "$work/out$other" \
      : -np 1 "$fiberfluid" run "$work/$other/exp.json" -q -o "$work/out$other" \
      >"$work/log" 2>&1
    status=$?
    [ $status -ne 124 ] || fail "A : $other hung"
    [ $status -eq 1 ] || fail "A : $other: status $status: $(cat "$work/log")"
    grep -q "MPI rank(s) 1 read another experiment or surface than rank 0" "$work/log" ||
      fail "A : $other: $(cat "$work/log")"
    [ ! -e "$work/out$other" ] || fail "A : $other wrote a result"
    [ -z "$(ls "$work" | grep running)" ] || fail "A : $other left a staging folder"
  done
  # A failure on one rank alone, outside any work item (injected), while the
  # other waits for it: the whole job ends, naming the rank, and leaves no
  # result or staging folder.
  for rank in 0 1; do
    FIBERFLUID_FAIL_RANK=$rank timeout 120 "${mpirun[@]}" -np 2 "$fiberfluid" run \
      "$work/A/exp.json" -q -o "$work/fail$rank" >"$work/log" 2>&1
    status=$?
    [ $status -ne 124 ] || fail "a failure on rank $rank alone: the job hung"
    [ $status -ne 0 ] || fail "a failure on rank $rank alone: status 0"
    grep -q "MPI rank $rank of 2 failed alone" "$work/log" || fail "rank $rank: $(cat "$work/log")"
    [ ! -e "$work/fail$rank" ] || fail "rank $rank: a result was written"
  done
  # The same experiment on both ranks still runs.
  "${mpirun[@]}" -np 2 "$fiberfluid" run "$work/A/exp.json" -q -o "$work/same" >/dev/null 2>&1 ||
    fail "the same experiment on two ranks"
  ;;
*)
  fail "unknown case $case_name"
  ;;
esac
echo "ok: $case_name"
