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

// The parameters `held` (indices) that the data cannot see: named in
// result.unseen and status_detail, their standard errors and intervals
// NaN (describe_estimates gave them a variance of 0).
void describe_unseen(const std::vector<int>& held, FitResult& result);

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

// The parameters the data cannot see one by one, to hold when J is rank
// deficient: a column that is 0 or not finite, and a parameter on a bound
// (a log-scaled one sunk to its lower bound loses its column). Parameters
// that are each seen but cannot be told apart are not among them: holding
// one would pass off the others' conditional intervals as theirs.
std::vector<int> parameters_to_hold(const Eigen::MatrixXd& J, const Variables& map,
                                    const Eigen::VectorXd& phi);

}  // namespace fiberfluid::fit
