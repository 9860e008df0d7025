#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, with ASan and UBSan, in
# build-fuzz/) and runs each for SECONDS (default 60), as many at once as
# there are cores (or FUZZ_JOBS). Each starts from its corpus: the seeds in tests/fuzz/seeds,
# the repository's meshes or experiments, and what earlier runs here added
# (build-fuzz/corpus). A crash, a hang past 25 s, a leak or a broken invariant
# stops that target: its input is copied to tests/fuzz/regressions/TARGET/,
# where the test suite replays it, and the script exits 1.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     targets: obj off stl_ascii stl_binary
#                                             ply_ascii ply_binary experiment model_setup
#                                             fit_section compare_2d compare_3d material_test
#
# A target with a dictionary (tests/fuzz/dictionaries/TARGET.dict: the
# fields, names and path pieces it is likely to miss) is given it.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
all=(obj off stl_ascii stl_binary ply_ascii ply_binary experiment model_setup fit_section
     compare_2d compare_3d material_test)
targets=("${@:-${all[@]}}")

scripts/install-deps.sh
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DFIBERFLUID_FUZZ=ON -DFIBERFLUID_BUILD_TESTS=OFF -DFIBERFLUID_BUILD_PYTHON=OFF \
  -DFIBERFLUID_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/#/fuzz_}" >/dev/null

export ASAN_OPTIONS=detect_leaks=1
export UBSAN_OPTIONS="print_stacktrace=1:suppressions=$PWD/tests/sanitize/ubsan.supp"

# The repository's own files of a target's kind, beside its seeds.
shared_inputs() {
  case "$1" in
    obj) ls data/meshes/*.obj data/targets/*.obj ;;
    stl_*) ls data/meshes/*.stl ;;
    experiment | model_setup | fit_section) ls experiments/*.json ;;
    compare_*) ls data/meshes/*.obj ;;
    material_test) ls data/measurements/treloar_rubber/*.csv ;;
  esac
}

fuzz_one() {
  local target=$1 corpus=build-fuzz/corpus/$1 artifacts=build-fuzz/artifacts/$1/
  mkdir -p "$corpus" "$artifacts"
  cp -n tests/fuzz/seeds/"$target"/* "$corpus"/ 2>/dev/null || true
  for f in $(shared_inputs "$target"); do cp -n "$f" "$corpus"/; done
  local log=build-fuzz/$target.log status=0
  local dictionary=()
  [ -f tests/fuzz/dictionaries/"$target".dict ] && dictionary=(-dict=tests/fuzz/dictionaries/"$target".dict)
  build-fuzz/tests/fuzz/fuzz_"$target" "$corpus" "${dictionary[@]}" -max_total_time="$seconds" -timeout=25 \
    -rss_limit_mb=3072 -max_len=65536 -print_final_stats=1 -artifact_prefix="$artifacts" \
    >"$log" 2>&1 || status=$?
  local runs cov ft corp
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  corp=$(ls "$corpus" | wc -l)
  if [ "$status" -ne 0 ]; then
    mkdir -p tests/fuzz/regressions/"$target"
    cp "$artifacts"* tests/fuzz/regressions/"$target"/ 2>/dev/null || true
    echo "$target: FOUND A FAILURE after ${runs:-?} runs (build-fuzz/$target.log; input copied to tests/fuzz/regressions/$target/)"
    grep -m5 -E 'ERROR|invariant|runtime error|terminate' "$log" | sed 's/^/    /'
    return 1
  fi
  printf '%-12s %6s s %10s runs %8s/s  edges %5s  features %6s  corpus %5s  findings 0\n' \
    "$target" "$seconds" "${runs:-0}" "$(( ${runs:-0} / seconds ))" "${cov:-?}" "${ft:-?}" "$corp"
}

failed=0
running=0
for target in "${targets[@]}"; do
  fuzz_one "$target" &
  running=$((running + 1))
  if [ "$running" -ge "${FUZZ_JOBS:-$(nproc)}" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
[ "$failed" -eq 0 ] && echo "fuzzing: ${#targets[@]} targets, ${seconds} s each, no failure"
exit "$failed"
