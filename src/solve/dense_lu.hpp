// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/solve/status.hpp"

namespace fiberfluid::solve {

// LU with partial pivoting of a dense square matrix through LAPACK (dgetrf),
// the paper's method. Factor once, then solve for as many right-hand sides as
// needed while the matrix is unchanged.
class DenseLU {
 public:
  // Fails when the matrix is singular or its reciprocal condition number
  // (1-norm estimate, dgecon) is below 10 machine epsilons.
  Status factorize(const Eigen::MatrixXd& A);
  // Requires a successful factorize().
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  double reciprocal_condition() const { return rcond_; }

 private:
  Eigen::MatrixXd lu_;
  std::vector<int> pivots_;
  double rcond_ = 0.0;
  bool factored_ = false;
};

}  // namespace fiberfluid::solve
