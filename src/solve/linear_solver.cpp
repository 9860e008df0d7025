// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/linear_solver.hpp"

#include <sstream>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

const char* to_string(SolverKind kind) {
  switch (kind) {
    case SolverKind::Auto:
      return "auto";
    case SolverKind::DenseLU:
      return "dense-lu";
    case SolverKind::BlockCholesky:
      return "block-cholesky";
    case SolverKind::Cholmod:
      return "cholmod";
    case SolverKind::PCG:
      return "pcg";
  }
  return "?";
}

namespace {
constexpr SolverKind kEverySolver[] = {SolverKind::Auto, SolverKind::DenseLU,
                                       SolverKind::BlockCholesky, SolverKind::Cholmod,
                                       SolverKind::PCG};
}  // namespace

std::optional<SolverKind> solver_kind_from_string(const std::string& name) {
  for (SolverKind kind : kEverySolver)
    if (name == to_string(kind)) return kind;
  return std::nullopt;
}

std::vector<std::string> solver_kind_names() {
  std::vector<std::string> names;
  for (SolverKind kind : kEverySolver) names.push_back(to_string(kind));
  return names;
}

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
