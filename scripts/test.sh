#!/usr/bin/env bash
# Builds fiberfluid with its tests (RelWithDebInfo) and runs them all; then
# builds the suite again with AddressSanitizer and UndefinedBehaviorSanitizer
# (build-sanitize/) and runs it there too; then runs each fuzz target for 30 s.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"

# The sanitized run (ASan + UBSan; every finding is fatal). Left out, with
# their reasons: the Python module and the installed example (a shared object
# loaded by an unsanitized interpreter or toolchain), and the two longest
# experiments, which the run above covers: bunny_gravity (930k fiber pairs
# pruned: minutes under ASan; the pruning tests run here on smaller bodies)
# and benchmark_rod (a calibration loop of the rod's fiber model); and the
# central-fiber bar on its finer mesh and under its weight (bar_bending: dense
# Newton on 1,000 to 2,200 unknowns; the coarse bar's tests run here); the
# soft cylinder bending far (cantilever_large and its fit: a nonlinear FEM of
# 9,500 tetrahedra, its committed target checked again, and a 2-parameter fit
# of 40 dense-Newton runs); and the block benchmark's finer mesh
# (benchmark_block_mp2: the same code as benchmark_block_mp1, two minutes under ASan).
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFIBERFLUID_SANITIZE=ON \
      -DFIBERFLUID_BUILD_PYTHON=OFF -DFIBERFLUID_BUILD_BENCHMARKS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-sanitize -j"$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS="print_stacktrace=1:suppressions=$PWD/tests/sanitize/ubsan.supp"
start=$(date +%s)
ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" \
      -E 'install\.|bunny_gravity\.json|benchmark_rod\.json|bar_bending\.json|cantilever_large\.json|TheCommittedCantileverTargetIsCurrent|TheBarsProfileHoldsAsTheMeshIsRefined|benchmark_block_mp2\.json'
echo "sanitized tests (ASan + UBSan): passed in $(( $(date +%s) - start )) s"

# The libFuzzer targets (clang, ASan + UBSan, build-fuzz/), each for 30 s from
# its seeds: a crash, hang, leak or broken invariant fails the run and leaves
# its input in tests/fuzz/regressions/ (scripts/fuzz.sh).
scripts/fuzz.sh 30
