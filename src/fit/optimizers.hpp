// SPDX-License-Identifier: GPL-3.0-or-later
// The optimisers behind Calibration::run (internal header): Ceres and NLopt
// stay inside their .cpp files.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/problem.hpp"

namespace fiberfluid::fit {

struct OptimizerOutcome {
  // Converged, IterationLimit, ForwardRunsFailed, OptimizerFailed or Interrupted.
  FitStatus status = FitStatus::OptimizerFailed;
  std::string message;
  Eigen::VectorXd phi;  // the best point found
  std::vector<IterationRecord> iterations;
};

// A Levenberg-Marquardt iteration's record from Ceres' summary (its number,
// whether its step was taken, the cost there), after the `earlier` ones: a
// rejected step's record keeps the current (last accepted) cost.
IterationRecord lm_iteration(int iteration, bool step_taken, double cost,
                             const std::vector<IterationRecord>& earlier);

// Each from the fitted variables `start`.
OptimizerOutcome fit_levenberg_marquardt(EvaluationCache& evaluations, const FitOptions& options,
                                         const Eigen::VectorXd& start);
// NLopt's methods minimise the problem's cost under its loss.
OptimizerOutcome fit_nlopt(EvaluationCache& evaluations, const FitProblem& problem,
                           const FitOptions& options, const Eigen::VectorXd& start);

// The covariance of the fitted variables phi at the optimum (Ceres
// Covariance, unscaled: (J^T J)^-1 of the robustified residuals), or false
// when J is rank deficient.
// `held`: fitted variables taken as known (a parameter the data cannot see):
// their rows and columns are 0, and the others' covariance is that of a fit
// with them fixed.
bool phi_covariance(EvaluationCache& evaluations, const FitOptions& options,
                    const Eigen::VectorXd& phi, Eigen::MatrixXd* covariance,
                    const std::vector<int>& held = {});

}  // namespace fiberfluid::fit
