// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// What a case will cost before it runs: memory and time from the mesh size,
// the backend and the steps, so that a run that cannot fit is refused before
// it starts, and a long one says how long it will take.

#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/resource_estimate.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/cost_model.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {

struct CaseSpec;  // case_spec.hpp, which keeps an estimate in each Case

// This machine's kernel speeds (solve/cost_model.hpp).
using KernelSpeed = solve::KernelSpeed;

// What the fibers cost before the solve: nothing (pruning off), the
// convexity check (a convex body, or before the check has said), or the
// check and the exact pruning of a concave body.
enum class PruningWork { None, ConvexityCheck, Prune };

// The estimate for a model whose supports are set (the backend and its
// block sizes follow from them, as solve::choose_solver does) with the
// stepping options it will run with.
ResourceEstimate estimate_resources(const model::Model& model,
                                    const solve::SteppingOptions& stepping, PruningWork pruning,
                                    const KernelSpeed& speed = {});

// Throws InputError naming the spec's file when the estimate exceeds the
// memory budget (fiberfluid::memory_budget_bytes()) or the time budget:
// what it needs, the budget, and what lifts the limit (--max-memory or
// --max-time, the pcg solver, a coarser mesh).
void require_within_budget(const ResourceEstimate& estimate, const CaseSpec& spec);

// This process's peak resident memory so far, in bytes (0 when unknown).
double peak_resident_bytes();

// A duration as an estimate prints it: "0.5 s", "40 s", "12 min", "3.6 h".
std::string seconds_text(double seconds);

}  // namespace fiberfluid::experiment
