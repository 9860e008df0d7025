// SPDX-License-Identifier: GPL-3.0-or-later
// make_linear_solver (linear_solver.hpp): the one factory over the backends,
// beside their own factories (backends.hpp), so that the interface's file
// does not include what builds on it.
#include "fiberfluid/solve/backends.hpp"

namespace fiberfluid::solve {

std::unique_ptr<LinearSolver> make_linear_solver(SolverKind kind, const PcgOptions& pcg) {
  switch (kind) {
    case SolverKind::DenseLU:
      return make_dense_lu_solver();
    case SolverKind::BlockCholesky:
      return make_block_cholesky_solver();
    case SolverKind::Cholmod:
      return make_cholmod_solver();
    case SolverKind::PCG:
      return make_pcg_solver(pcg);
    case SolverKind::Auto:
      break;
  }
  return nullptr;
}

}  // namespace fiberfluid::solve
