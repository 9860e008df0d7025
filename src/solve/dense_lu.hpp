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
  // (A by value: pass it moved to factor it in place.)
  Status factorize(Eigen::MatrixXd A);
  // For a preconditioner, after a successful factorize(): rounds the factors
  // to single precision when the preconditioned operator A M^-1 of the
  // rounded factors M stays within 1% of the identity (its largest stretch
  // |A M^-1 v - v| / |v| found by 4 power steps, each one rounded solve and
  // one product with the double factors), and says whether it did. The
  // condition number bounds that stretch far above what it is (3e6 times
  // float's epsilon, 0.2, on the bending phantoms). A solve reads the whole
  // factor and is memory-bound: half the bytes halve its time (issue 42,
  // 4,254 unknowns: 8 ms against 17 ms, most of a phantom's run).
  bool round_to_single();
  double rounding_stretch() const { return rounding_stretch_; }
  bool single() const { return single_; }
  // Requires a successful factorize().
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  double reciprocal_condition() const { return rcond_; }

 private:
  static constexpr int kRoundingPowerSteps = 4;
  static constexpr double kMostRoundingStretch = 0.01;
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;

  Eigen::MatrixXd lu_;
  Eigen::MatrixXf lu_single_;
  double rounding_stretch_ = 0.0;
  bool single_ = false;
  std::vector<int> pivots_;
  double rcond_ = 0.0;
  bool factored_ = false;
};

}  // namespace fiberfluid::solve
