// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// What a case will cost before it runs: memory and time from the mesh size,
// the backend and the steps, so that a run that cannot fit is refused before
// it starts, and a long one says how long it will take.

#include <string>
#include <vector>

#include "geom/surface.hpp"

namespace fiberfluid::app {

struct CaseSpec;  // case_spec.hpp, which keeps an estimate in each Case

// This machine's speed for the kernels the estimate counts (Release build,
// all cores). Measured here with experiments/resources (scripts/resources.sh):
// rerun it and put the figures here on another machine.
struct KernelSpeed {
  double prune_pairs_per_second = 1.1e5;        // exact pruning, pair tests (concave bodies)
  double orientation_tests_per_second = 3e8;    // the convexity check: N x F orientation tests
  double dense_flops_per_second = 3e10;         // LAPACK dgetrf / dpotrf on large matrices
  double pair_updates_per_second = 4e8;         // one fiber pair in a product or an assembly
  double sparse_flops_per_second = 3e9;         // CHOLMOD on pruned or surface-tension blocks
};

struct ResourcePart {
  std::string name;     // "pruning", "factorisation", "load steps" ...
  double bytes = 0.0;   // held while this part runs (and after, for the kept parts)
  double seconds = 0.0;
  bool kept = false;    // still held by the later parts (the fiber table)
};

struct ResourceEstimate {
  std::vector<ResourcePart> parts;
  std::string solver;        // the backend assumed ("block-cholesky", ...)
  double peak_bytes = 0.0;   // the largest part plus what the kept parts hold
  double seconds = 0.0;      // all parts
  // "about 1.2 GiB and 40 s (pruning 30 s, factorisation 8 s, 10 load steps 2 s)".
  std::string describe() const;
};

// The estimate for a case on its model surface (every vertex used), with
// `concave`: its fibers will be pruned exactly. With pruning on, the
// convexity check that decides it is counted too (its worst case).
ResourceEstimate estimate_resources(const CaseSpec& spec, const geom::Surface& model_surface,
                                    bool concave, const KernelSpeed& speed = {});

// Throws InputError naming the spec's file when the estimate exceeds the
// memory budget (fiberfluid::memory_budget_bytes()) or the time budget:
// what it needs, the budget, and what lifts the limit (--max-memory or
// --max-time, the pcg solver, a coarser mesh).
void require_within_budget(const ResourceEstimate& estimate, const CaseSpec& spec);

// This process's peak resident memory so far, in bytes (0 when unknown).
double peak_resident_bytes();

}  // namespace fiberfluid::app
