// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include "fiberfluid/solve/linear_solver.hpp"

namespace fiberfluid::solve {

// Eliminates P by a Schur complement (model.md section 5): with the border
// s, K z = s once per factorisation, then per right-hand side [f; c]:
//   K w = f,  P = (s.w - c) / (s.z),  u = w - P z.
// Subclasses provide the block solves with K.
class SchurSolver : public LinearSolver {
 public:
  Status factorize(const model::BorderedSystem& system) final;
  Status solve(const Eigen::VectorXd& rhs, Eigen::VectorXd* solution) final;

 protected:
  virtual Status factorize_K(const model::BorderedSystem& system) = 0;
  // Solves K w = f over the reduced displacement unknowns.
  virtual Status solve_K(const Eigen::VectorXd& f, Eigen::VectorXd* w) = 0;

 private:
  Eigen::VectorXd border_, z_;
  double s_dot_z_ = 0.0;
};

}  // namespace fiberfluid::solve
