// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/linear_solver.hpp"

#include <sstream>

#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

SolverKind choose_solver(double largest_block, int factors, double budget_bytes) {
  const double n = largest_block;
  if (n <= 600) return SolverKind::DenseLU;  // the paper's method, well within a second
  if (8.0 * n * n * (factors + 1) < 0.375 * budget_bytes) return SolverKind::BlockCholesky;
  return SolverKind::PCG;
}

SolverKind choose_solver(const model::BorderedSystem& system, double budget_bytes) {
  // Sparse blocks (a horizon's fibers): CHOLMOD, whose factor grows with the
  // neighbours rather than N^2.
  if (!system.dense_blocks() && system.largest_block() > 600) return SolverKind::Cholmod;
  return choose_solver(system.largest_block(), system.blocks_equal() ? 1 : system.num_blocks(),
                       budget_bytes);
}

SolverKind choose_solver(const model::BorderedSystem& system) {
  return choose_solver(system, memory_budget_bytes());
}

Status require_memory(double bytes, const std::string& what) {
  const double budget = memory_budget_bytes();
  if (bytes <= budget) return {};
  std::ostringstream out;
  out << what << " needs about " << format_bytes(bytes) << ", more than the memory budget of "
      << format_bytes(budget)
      << (memory_budget_is_set() ? " (--max-memory)" : " (80% of this machine's memory)")
      << "; use the pcg solver or a coarser mesh"
      << (memory_budget_is_set() ? ", or raise --max-memory" : "");
  return Status::failure(out.str());
}

}  // namespace fiberfluid::solve
