// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/schur_solver.hpp"

#include <cmath>

namespace fiberfluid::solve {

Status SchurSolver::factorize(const model::BorderedSystem& system) {
  Status status = factorize_K(system);
  if (!status.ok) return status;
  border_ = system.border();
  status = solve_K(border_, &z_);
  if (!status.ok) return status;
  s_dot_z_ = border_.dot(z_);
  // K is positive definite, so s.z > 0 unless the border vanishes on every
  // free unknown: then nothing determines P.
  if (!(s_dot_z_ > 1e-300) || !std::isfinite(s_dot_z_))
    return Status::failure(
        "the pressure is undetermined: the area vectors vanish on every free "
        "unknown (too many supports?)");
  return {};
}

Status SchurSolver::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd* solution) {
  const Eigen::Index m = border_.size();
  Eigen::VectorXd w;
  const Status status = solve_K(rhs.head(m), &w);
  if (!status.ok) return status;
  ++statistics_.solves;
  const double pressure = (border_.dot(w) - rhs[m]) / s_dot_z_;
  solution->resize(m + 1);
  solution->head(m) = w - pressure * z_;
  (*solution)[m] = pressure;
  return {};
}

}  // namespace fiberfluid::solve
