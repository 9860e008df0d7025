// SPDX-License-Identifier: GPL-3.0-or-later
// What a converged fit's estimate is worth (internal to fit/): the
// parameters on their bounds, the standard errors, 95% intervals and
// correlations from the covariance, the intervals' ends checked on the
// profile likelihood, and why a Jacobian cannot separate its parameters.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/fit/problem.hpp"

namespace fiberfluid::fit {

class EvaluationCache;

// The parameters on a bound at phi, into FitResult::at_bounds and
// status_detail (with_correlation: each with its strongest correlation).
void describe_bounds(const Variables& map, const Eigen::VectorXd& phi, bool with_correlation,
                     FitResult& result);

// From the covariance of phi (unscaled) and the residual variance: the
// correlations, the bounds again with them, and for every parameter off its
// bounds the standard error and the linearised 95% interval (in log scale
// for a log-scaled parameter, so that it stays positive).
void describe_estimates(const Variables& map, const Eigen::VectorXd& phi,
                        const Eigen::MatrixXd& covariance, double variance, FitResult& result);

// The linearised 95% intervals' ends checked on the profile likelihood: an
// end where it has risen by less than half the 95% level is moved out to
// where it reaches the level, or to the parameter's bound.
void check_interval_ends(EvaluationCache& evaluations, const FitProblem& problem,
                         const Eigen::VectorXd& phi, const Eigen::MatrixXd& covariance,
                         double variance, FitResult& result);

// Why a Jacobian cannot separate its parameters: a column that is zero or
// not finite (no distance changes with that parameter), else the
// combination its smallest singular value leaves unseen.
std::string unidentifiable_because(const Eigen::MatrixXd& J, const std::vector<std::string>& names);

}  // namespace fiberfluid::fit
