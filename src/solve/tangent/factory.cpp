// SPDX-License-Identifier: GPL-3.0-or-later
// The tangent strategies by kind: which one `auto` picks, how each is made
// and what each costs (the strategies themselves are one file each).
#include <stdexcept>
#include <string>

#include "fiberfluid/solve/tangent/strategies.hpp"
#include "fiberfluid/solve/tangent/tangent_solve.hpp"

namespace fiberfluid::solve {

TangentSolver choose_tangent(TangentSolver requested, int reduced_unknowns,
                             model::FiberKinematics kinematics, bool sparse_fibers) {
  if (requested != TangentSolver::Auto) return requested;
  // The vector spring's own secant preconditioner fits its tangent at any size.
  if (kinematics == model::FiberKinematics::VectorSpring)
    return reduced_unknowns <= 600 ? TangentSolver::Dense : TangentSolver::Krylov;
  // Krylov's secant preconditioner is far from a central tangent (GMRES
  // stalls once contact and large rotations couple the axes). Where the
  // fibers are many (every pair, or a horizon that keeps more than an eighth
  // of them), one dense LU of the tangent preconditions GMRES on the exact
  // tangent over many iterations and steps: above 600 unknowns that beats an
  // LU per iteration (issue 42: a bending phantom of 1,418 vertices in 10 s
  // with one LU, against 70 s with 34).
  if (reduced_unknowns > 50000) return TangentSolver::Krylov;
  if (reduced_unknowns <= 600) return TangentSolver::Dense;
  if (!sparse_fibers) return TangentSolver::Reused;
  // A horizon's lists: the tangent has N times the neighbours entries, and
  // its sparse LU beats the dense one above 600 unknowns (2,600: 0.3 s an
  // iteration against 0.8 s). Reusing that LU pays once its factorisation
  // outweighs GMRES's products (6,000 unknowns: 1.4 s a factorisation; the
  // reuse 2.6 times faster at small strains, 1.2 times on a cylinder bending
  // under its weight), not below (a bar of 729 unknowns bent to 37%: 2.3
  // times slower). docs/model.md, the table of `auto`.
  return reduced_unknowns <= 4000 ? TangentSolver::Sparse : TangentSolver::Reused;
}

namespace {

// One row per strategy: how it is made and what it costs.
struct Strategy {
  TangentSolver kind;
  std::unique_ptr<TangentSolve> (*make)(SharedEquilibrium, const SteppingOptions&);
  TangentCost (*cost)(const TangentCostCase&, const KernelSpeed&);
};
constexpr Strategy kStrategies[] = {
    {TangentSolver::Dense, make_dense_tangent, dense_tangent_cost},
    {TangentSolver::Sparse, make_sparse_tangent, sparse_tangent_cost},
    {TangentSolver::Krylov, make_secant_krylov, secant_krylov_cost},
    {TangentSolver::Reused, make_reused_tangent, reused_tangent_cost},
};

const Strategy& strategy(TangentSolver kind) {
  for (const Strategy& s : kStrategies)
    if (s.kind == kind) return s;
  throw std::logic_error(std::string("no tangent strategy \"") + to_string(kind) +
                         "\" (choose_tangent resolves auto first)");
}

}  // namespace

std::unique_ptr<TangentSolve> make_tangent_solve(
    std::shared_ptr<const model::Equilibrium> equilibrium, const SteppingOptions& options,
    TangentSolver kind) {
  return strategy(kind).make(std::move(equilibrium), options);
}

TangentCost tangent_cost(TangentSolver kind, const TangentCostCase& c, const KernelSpeed& speed) {
  return strategy(kind).cost(c, speed);
}

SolverKind tangent_factor_backend(TangentSolver kind, bool sparse_fibers, SolverKind structured) {
  const bool dense_factor =
      kind == TangentSolver::Dense || (kind == TangentSolver::Reused && !sparse_fibers);
  return dense_factor ? SolverKind::DenseLU : structured;
}

}  // namespace fiberfluid::solve
