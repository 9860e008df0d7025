// SPDX-License-Identifier: GPL-3.0-or-later
// The sparse tangent: the equilibrated sparse LU (UMFPACK) of the reduced
// tangent at every Newton iteration, for fibers within a horizon stored as
// lists (the tangent has N times the neighbours entries).
#include <cmath>

#include "fiberfluid/solve/tangent/strategies.hpp"
#include "fiberfluid/solve/tangent/tangent_lu.hpp"

namespace fiberfluid::solve {
namespace {

class SparseTangent final : public TangentSolve {
 public:
  SparseTangent(SharedEquilibrium equilibrium, const SteppingOptions& options)
      : TangentSolve(std::move(equilibrium), options, TangentSolver::Sparse, options.solver) {}

  Status prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) override {
    take_state(x, factors, dofs, preconditioner_dofs);
    const Status status = lu_.factor(*equilibrium_, x_, factors_, dofs_, added_);
    ++factorizations_;
    if (!status.ok) return Status::failure("newton: the tangent: " + status.message);
    ready_ = true;
    return {};
  }

  Status solve(const Eigen::VectorXd& b, double, Eigen::VectorXd* y, int*) override {
    if (!ready_) return Status::failure("newton: the tangent was not prepared");
    *y = lu_.solve(b);
    if (!y->allFinite()) return Status::failure("newton: the sparse tangent's solve failed");
    return {};
  }

 private:
  TangentLU lu_{TangentLU::Storage::Sparse};
};

// The sparse LU's fill, from a measurement at 10,242 vertices (a horizon of
// a tenth of the radius: 2.28 million entries, 27.6 million in L and U, 3.7 s).
constexpr double kSparseFillPerEntry = 12.0;
constexpr double kSparseFactorEntries = 2.76e7, kSparseFactorSeconds = 3.7;

}  // namespace

std::unique_ptr<TangentSolve> make_sparse_tangent(SharedEquilibrium e, const SteppingOptions& o) {
  return std::make_unique<SparseTangent>(std::move(e), o);
}

// The tangent's entries are dim^2 (N + 2 pairs); the factors' fill grows as
// sqrt(N) and the flops as the fill^1.5 from the measurement above. A solve
// with the factors reads them once (12 bytes an entry) at about 4 GB/s.
SparseLUCost sparse_tangent_lu_cost(double N, double dim, double pairs) {
  const double entries = dim * dim * (N + 2.0 * pairs);
  const double factor_entries = kSparseFillPerEntry * entries * std::sqrt(N / 10242.0);
  return {12.0 * factor_entries + 3.0 * 16.0 * entries,
          kSparseFactorSeconds * std::pow(factor_entries / kSparseFactorEntries, 1.5),
          12.0 * factor_entries / 4e9};
}

// A sparse LU and a residual per Newton iteration.
TangentCost sparse_tangent_cost(const TangentCostCase& c, const KernelSpeed&) {
  const SparseLUCost lu = sparse_tangent_lu_cost(c.vertices, c.dim, c.pairs);
  const double iterations = c.steps * kNewtonIterationsPerStep;
  return {lu.bytes, iterations * (lu.factor_seconds + c.residual_seconds)};
}

}  // namespace fiberfluid::solve
