// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/tangent/tangent_solve.hpp"

namespace fiberfluid::solve {

TangentSolve::TangentSolve(std::shared_ptr<const model::Equilibrium> equilibrium,
                           const SteppingOptions& options, TangentSolver kind,
                           SolverKind preconditioner_kind)
    : equilibrium_(std::move(equilibrium)),
      options_(options),
      preconditioner_kind_(preconditioner_kind),
      kind_(kind) {}

void TangentSolve::take_state(const Eigen::VectorXd& x, const std::vector<double>& factors,
                              const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) {
  x_ = x;
  factors_ = factors;
  dofs_ = dofs;
  preconditioner_dofs_ = preconditioner_dofs ? *preconditioner_dofs : dofs;
  ready_ = false;
}

Eigen::VectorXd TangentSolve::residual(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors) {
  return equilibrium_->residual(x, factors);
}

Status TangentSolve::solve_full(const Eigen::VectorXd& b, Eigen::VectorXd* y, double tolerance) {
  Eigen::VectorXd reduced;
  const Status status = solve(dofs_.reduce(b), tolerance, &reduced);
  if (!status.ok) return status;
  *y = Eigen::VectorXd::Zero(b.size());
  dofs_.scatter(reduced, *y);
  return {};
}

}  // namespace fiberfluid::solve
