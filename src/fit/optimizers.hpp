// SPDX-License-Identifier: GPL-3.0-or-later
// The optimisers behind Calibration::run (internal header): Ceres and NLopt
// stay inside their .cpp files.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fit/calibration.hpp"

namespace fiberfluid::fit {

struct OptimizerOutcome {
  bool success = false;
  std::string message;
  Eigen::VectorXd phi;                    // the best point found
  std::vector<IterationRecord> iterations;
  int forward_runs = 0, sensitivity_solves = 0;
  int failed_runs = 0;  // trial points whose forward run failed (rejected, not fatal)
};

OptimizerOutcome fit_levenberg_marquardt(const Calibration& calibration, const FitOptions& options);
OptimizerOutcome fit_nlopt(const Calibration& calibration, const FitOptions& options);

// The covariance of the fitted variables phi at the optimum (Ceres
// Covariance, unscaled: (J^T J)^-1 of the robustified residuals), or false
// when J is rank deficient. Counts its forward runs.
bool phi_covariance(const Calibration& calibration, const FitOptions& options,
                    const Eigen::VectorXd& phi, Eigen::MatrixXd* covariance, int* forward_runs);

}  // namespace fiberfluid::fit
