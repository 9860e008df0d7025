// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A prediction with bands (`fiberfluid predict`): another experiment run at a
// fit's values, its figures and force rows given 95% bands by carrying the
// fit's covariance through the Newton sensitivities of the run (first order,
// the delta method: var f = g^T C g, g = df/dphi).

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::experiment {

// What a fit folder's fit.json says of its estimate.
struct FittedEstimate {
  std::filesystem::path source;  // the fit.json read
  std::string experiment, status;
  std::vector<std::string> names;  // every fitted parameter, with its value
  Eigen::VectorXd values;
  // The parameters with a standard error, and the covariance of their fitted
  // variables phi (log theta for a log-scaled one, as the fit varied them).
  std::vector<std::string> banded;
  std::vector<bool> banded_log_scale;
  Eigen::MatrixXd covariance;
  // One line per fitted parameter without a band (on its bound, or with no
  // standard error): it is held at its value.
  std::vector<std::string> held;
};

// Reads FIT_FOLDER/fit.json. Throws InputError naming the file and field:
// no such file, not a fit's result, a fit that did not converge.
FittedEstimate read_fitted_estimate(const std::filesystem::path& fit_folder);

// Sets every case's parameters to the estimate's values by name, and asks
// each case's run for the sensitivities to the banded ones at every step.
// Throws InputError naming what stands in the way: not a simulation, a
// parameter the experiment's material does not have, a scheme other than
// Newton (stepping.scheme), a set-up whose sensitivities are not exact.
void apply_estimate(const FittedEstimate& estimate, Experiment& experiment);

// The bands of every run of `result`, from the sensitivities each step
// holds; `unknowns[run][k]` is the state after step k + 1 (where the largest
// displacement is).
std::vector<RunBands> prediction_bands(const Experiment& experiment, const ExperimentResult& result,
                                       const FittedEstimate& estimate,
                                       const std::vector<std::vector<Eigen::VectorXd>>& unknowns);

}  // namespace fiberfluid::experiment
