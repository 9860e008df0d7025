// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <string>

#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {

// The outcome of one case (Experiment::cases, same index).
struct RunResult {
  std::string variant;
  solve::SteppingSummary summary;
  int rank = 0;  // the MPI rank that ran it
  // The bordered matrix the backend factored last, dense, when an expected
  // figure checks it ("system_matrix"); else empty.
  Eigen::MatrixXd system_matrix;
};

}  // namespace fiberfluid::experiment
