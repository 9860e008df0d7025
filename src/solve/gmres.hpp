// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <functional>

#include "fiberfluid/solve/status.hpp"

namespace fiberfluid::solve {

using LinearOperator = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

struct GmresOptions {
  double tolerance = 1e-10;  // stop at |b - A x| <= tolerance |b|
  int restart = 50;          // Krylov vectors kept between restarts
  int max_iterations = 500;  // over all restarts
};

struct GmresResult {
  Status status;
  int iterations = 0;
  double relative_residual = 0.0;
};

// Restarted GMRES with right preconditioning, A M^{-1} y = b, x = M^{-1} y,
// so the residual it watches is the true one. x holds the initial guess
// (resized to zero when empty). Breakdown, a non-finite value or no
// convergence in max_iterations come back as a failed status.
GmresResult gmres(const LinearOperator& A, const LinearOperator& preconditioner,
                  const Eigen::VectorXd& b, Eigen::VectorXd& x, const GmresOptions& options);

}  // namespace fiberfluid::solve
