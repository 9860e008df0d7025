#!/usr/bin/env bash
# Builds fiberfluid with its tests (RelWithDebInfo) and runs them all; then
# builds the libFuzzer targets (clang, ASan + UBSan) and runs each for 20 s.
# The whole suite under ASan + UBSan is scripts/sanitize.sh: a third build and
# 15 minutes of tests, too long for CI's 90 minutes on a loaded machine.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
# Line tables only (-g1): failures keep their file and line, and the build is
# faster than with full debug information.
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null  # Debian's, with the numpy it installs
phase() { echo "== $1: $(( SECONDS - phase_start )) s"; phase_start=$SECONDS; }  # CI's time, by part
phase_start=$SECONDS
cmake --build build -j"$(nproc)"
phase "build"
ctest --test-dir build --output-on-failure -j"$(nproc)"
phase "tests"

# The libFuzzer targets (clang, ASan + UBSan, build-fuzz/), each for 20 s from
# its seeds: a crash, hang, leak or broken invariant fails the run and leaves
# its input in tests/fuzz/regressions/ (scripts/fuzz.sh).
scripts/fuzz.sh 20
phase "fuzzing"
