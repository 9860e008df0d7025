// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {

// A predicted value and its standard deviation; the 95% band is value +-
// 1.96 sd. NaN sd: no band (a mirror layer's reaction, nothing banded).
struct Band {
  double value = std::numeric_limits<double>::quiet_NaN();
  double sd = std::numeric_limits<double>::quiet_NaN();
  double lower95() const { return value - 1.96 * sd; }
  double upper95() const { return value + 1.96 * sd; }
};

// One run's bands: per step, by steps.csv column (pressure_Pa,
// max_displacement_m, reaction_GROUP_AXIS_N, paddle_LABEL_force_AXIS_N);
// and its figures by name (max_displacement, final_pressure,
// paddle_force.LABEL along its axis).
struct RunBands {
  std::vector<std::map<std::string, Band>> steps;
  std::map<std::string, Band> figures;
};

// The outcome of one case (Experiment::cases, same index).
struct RunResult {
  std::string variant;
  solve::SteppingSummary summary;
  int rank = 0;  // the MPI rank that ran it
  // The bordered matrix the backend factored last, dense, when an expected
  // figure checks it ("system_matrix"); else empty.
  Eigen::MatrixXd system_matrix;
  // A prediction's bands (`fiberfluid predict`), written beside steps.csv's
  // columns; empty otherwise.
  RunBands bands;
};

}  // namespace fiberfluid::experiment
