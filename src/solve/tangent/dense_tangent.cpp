// SPDX-License-Identifier: GPL-3.0-or-later
// The dense tangent: the equilibrated LU of the reduced tangent at every
// Newton iteration (exact Newton; small problems, where an LU costs little).
#include "fiberfluid/solve/tangent/strategies.hpp"
#include "fiberfluid/solve/tangent/tangent_lu.hpp"

namespace fiberfluid::solve {
namespace {

class DenseTangent final : public TangentSolve {
 public:
  DenseTangent(SharedEquilibrium equilibrium, const SteppingOptions& options)
      : TangentSolve(std::move(equilibrium), options, TangentSolver::Dense, SolverKind::DenseLU) {}

  Status prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) override {
    take_state(x, factors, dofs, preconditioner_dofs);
    const Status status = lu_.factor(*equilibrium_, x_, factors_, dofs_, added_);
    if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
    ready_ = true;
    return {};
  }

  Status solve(const Eigen::VectorXd& b, double, Eigen::VectorXd* y, int*) override {
    if (!ready_) return Status::failure("newton: the tangent was not prepared");
    *y = lu_.solve(b);
    return {};
  }

 private:
  TangentLU lu_{TangentLU::Storage::Dense};
};

}  // namespace

std::unique_ptr<TangentSolve> make_dense_tangent(SharedEquilibrium e, const SteppingOptions& o) {
  return std::make_unique<DenseTangent>(std::move(e), o);
}

// An LU of the backend's (the dense LU) and a residual per Newton iteration.
TangentCost dense_tangent_cost(const TangentCostCase& c, const KernelSpeed&) {
  const double iterations = c.steps * kNewtonIterationsPerStep;
  return {c.factor.factor_bytes, iterations * (c.factor.factor_seconds + c.residual_seconds)};
}

}  // namespace fiberfluid::solve
