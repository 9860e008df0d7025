#!/usr/bin/env bash
# The test suite built again with AddressSanitizer and UndefinedBehaviorSanitizer
# (build-sanitize/, every finding fatal, leaks too) and run there. Run it before
# landing a change to memory handling, the readers or the solvers; CI runs the
# fuzz targets under the same sanitizers (scripts/test.sh) but not this, whose
# build and tests take about 40 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
phase() { echo "== $1: $(( SECONDS - phase_start )) s"; phase_start=$SECONDS; }
phase_start=$SECONDS

# The sanitized run (ASan + UBSan; every finding is fatal). Left out, with
# their reasons: the Python module and the installed example (a shared object
# loaded by an unsanitized interpreter or toolchain), and the two longest
# experiments, which the plain run (scripts/test.sh) covers: bunny_gravity (930k fiber pairs
# pruned: minutes under ASan; the pruning tests run here on smaller bodies)
# and benchmark_rod (a calibration loop of the rod's fiber model); the
# central-fiber bar on its finer mesh and under its weight (bar_bending: dense
# Newton on 1,000 to 2,200 unknowns; the coarse bar's tests run here); the
# soft cylinder bending far (cantilever_large and its fit: a nonlinear FEM of
# 9,500 tetrahedra, its committed target checked again, and a 2-parameter fit
# of 40 dense-Newton runs); the liver's FEM reference and its committed target
# (quadratic tetrahedra with a pressure, 24,000 nodes: a minute here, far longer
# under ASan); the central fibers' mesh study (three cantilevers) and its cylinder;
# the block benchmark's two meshes (benchmark_block_mp1 and _mp2: the 2D FEM
# and the fiber model the Benchmark.* tests run here on the same scene, two
# minutes each under ASan); and long loops over code that shorter tests run here: the progress
# lines of two runs of 400 load steps (Cli.LongPhasesShowProgressUnlessQuiet), the FEM
# liver's fit and the exact synthetic liver's fit (fit_synthetic_liver.json
# runs the same fit), a fit driven onto its bounds (FitStatus.*Bounds*), the
# pruning against brute force on the shared meshes (100 s under ASan; the same
# comparison on generated bodies runs here), the finer liver's force-curve fit
# (fit_liver_force.json; ForceCurveFit.* fits force curves here), the resolved
# experiment's bit-for-bit round trip (three whole runs; the plain run checks
# the bits) and the fitted benchmark (Benchmark.TheFittedFiberModelIsTheClosest;
# the other Benchmark.* tests run here).
# Line tables only (-g1): ASan's reports keep their file and line, and the
# build is faster than with full debug information.
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFIBERFLUID_SANITIZE=ON \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
      -DFIBERFLUID_BUILD_PYTHON=OFF -DFIBERFLUID_BUILD_BENCHMARKS=OFF \
      -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build-sanitize -j"$(nproc)"
phase "sanitized build"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS="print_stacktrace=1:suppressions=$PWD/tests/sanitize/ubsan.supp"
ctest --test-dir build-sanitize --output-on-failure -j"$(nproc)" \
      -E 'install\.|bunny_gravity\.json|benchmark_rod\.json|benchmark_rod_converged\.json|bar_bending\.json|cantilever_large\.json|TheCommittedCantileverTargetAgreesWithTheCoarserReference|TheCommittedLiverTargetIsCurrent|liver_fem_reference\.json|CentralFibersByDefaultConvergeMonotonicallyWithTheMesh|cylinder_mesh_study\.json|TheBarsProfileHoldsAsTheMeshIsRefined|benchmark_block_mp[12]\.json|LongPhasesShowProgressUnlessQuiet|fit_liver_fem\.json|fit_synthetic_liver_exact\.json|ParametersOnTheirBoundsAreNamedWithTheirCorrelation|AgreesWithTheBruteForceOnSharedMeshes|fit_liver_force\.json|TheResolvedExperimentRepeatsTheRunBitForBit|TheFittedFiberModelIsTheClosest|ASurfaceBeyondTheBudgetsIsRefusedBeforeItIsBuiltAndStopsWhenAsked'
phase "sanitized tests (ASan + UBSan)"

