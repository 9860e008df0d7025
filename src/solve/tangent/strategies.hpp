// SPDX-License-Identifier: GPL-3.0-or-later
// The tangent strategies, each made and costed by its own file (internal to
// solve/tangent/; factory.cpp dispatches on the kind). A new strategy:
// its name in TangentSolver (stepping.hpp), a file here with its class, make
// and cost, a row in factory.cpp and one in solve/CMakeLists.txt.
#pragma once

#include <memory>

#include "fiberfluid/solve/tangent/tangent_solve.hpp"

namespace fiberfluid::solve {

// Typical counts where the work depends on the data (scripts/resources.sh:
// the sphere's Newton steps): Newton iterations per load step.
inline constexpr double kNewtonIterationsPerStep = 2.5;

using SharedEquilibrium = std::shared_ptr<const model::Equilibrium>;

std::unique_ptr<TangentSolve> make_dense_tangent(SharedEquilibrium e, const SteppingOptions& o);
std::unique_ptr<TangentSolve> make_sparse_tangent(SharedEquilibrium e, const SteppingOptions& o);
std::unique_ptr<TangentSolve> make_secant_krylov(SharedEquilibrium e, const SteppingOptions& o);
std::unique_ptr<TangentSolve> make_reused_tangent(SharedEquilibrium e, const SteppingOptions& o);

TangentCost dense_tangent_cost(const TangentCostCase& c, const KernelSpeed& speed);
TangentCost sparse_tangent_cost(const TangentCostCase& c, const KernelSpeed& speed);
TangentCost secant_krylov_cost(const TangentCostCase& c, const KernelSpeed& speed);
TangentCost reused_tangent_cost(const TangentCostCase& c, const KernelSpeed& speed);

// The sparse LU of a horizon's Newton tangent (UMFPACK): its bytes, one
// factorisation's seconds and one solve's.
struct SparseLUCost {
  double bytes, factor_seconds, solve_seconds;
};
SparseLUCost sparse_tangent_lu_cost(double N, double dim, double pairs);

}  // namespace fiberfluid::solve
