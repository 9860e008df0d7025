// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A run's outcome as bytes, for a run made on another MPI rank: everything of
// the run that its output files and figures are made from, bit for bit, with
// the unknowns after each step (replayed into the output writer on rank 0).
// The summary's live objects (the factored system, the final tangent) stay on
// the rank that ran it; the system's matrix travels when a check needs it.

#include <string>
#include <vector>

#include "fiberfluid/experiment/run/run_result.hpp"

namespace fiberfluid::experiment {

struct RunOutcome {
  RunResult run;
  std::vector<Eigen::VectorXd> step_unknowns;  // after each of run.summary.steps
};

std::string pack_run_outcome(const RunOutcome& outcome);
// Throws std::runtime_error when the bytes are not a packed outcome.
RunOutcome unpack_run_outcome(const std::string& bytes);

}  // namespace fiberfluid::experiment
