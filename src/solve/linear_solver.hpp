// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/model/bordered_system.hpp"
#include "fiberfluid/solve/status.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::solve {

// The linear backends for a bordered system (model::BorderedSystem: the
// fibers-and-fluid model's FiberSystem, or any K and border).
enum class SolverKind {
  Auto,           // chosen by size: choose_solver()
  DenseLU,        // the paper's method: LU of the whole reduced system (LAPACK)
  BlockCholesky,  // Schur complement on P, one dense Cholesky per axis block (LAPACK)
  Cholmod,        // Schur complement on P, sparse Cholesky per axis block (SuiteSparse)
  PCG,            // Schur complement on P, matrix-free preconditioned conjugate gradients
};
inline constexpr auto kSolverKindNames =
    names_of<SolverKind>({{SolverKind::Auto, "auto"},
                          {SolverKind::DenseLU, "dense-lu"},
                          {SolverKind::BlockCholesky, "block-cholesky"},
                          {SolverKind::Cholmod, "cholmod"},
                          {SolverKind::PCG, "pcg"}});
inline const char* to_string(SolverKind kind) { return kSolverKindNames.name(kind); }

struct PcgOptions {
  double tolerance = 1e-10;   // stop at |r| <= tolerance |b| (relative residual)
  int max_iterations = 1000;  // then fail with a status
};

// What a backend did, for the summaries.
struct SolverStatistics {
  double factorization_flops = 0.0;           // dense paths: the LAPACK factorisation's flop count
  double factorization_kernel_seconds = 0.0;  // time inside that LAPACK routine
  int iterations = 0;                         // pcg: iterations over all solves
  int solves = 0;
};

// analyze_pattern once per structure, factorize per matrix, solve per
// right-hand side. Expected numerical failures (not positive definite, no
// convergence, a system too large for memory) come back as a Status.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual SolverKind kind() const = 0;
  virtual Status analyze_pattern(const model::BorderedSystem& system) = 0;
  // The system must outlive the factorisation (pcg applies it in solve()).
  virtual Status factorize(const model::BorderedSystem& system) = 0;
  // rhs = [f; c] over the system's reduced unknowns; requires factorize().
  virtual Status solve(const Eigen::VectorXd& rhs, Eigen::VectorXd* solution) = 0;
  const SolverStatistics& statistics() const { return statistics_; }

 protected:
  SolverStatistics statistics_;
};

std::unique_ptr<LinearSolver> make_linear_solver(SolverKind kind, const PcgOptions& pcg = {});

// The default by size: the paper's dense LU for small systems, block
// Cholesky while its dense N x N blocks take at most 3/8 of `budget_bytes`
// (30% of the memory under the default budget of 80%), pcg beyond.
SolverKind choose_solver(const model::BorderedSystem& system, double budget_bytes);
// The same rule from the sizes alone: the largest axis block and the number
// of distinct block factors (1 when every axis block is equal).
SolverKind choose_solver(double largest_block, int factors, double budget_bytes);
// The same for the process's memory budget (memory_budget_bytes()).
SolverKind choose_solver(const model::BorderedSystem& system);

// A failure when `bytes` would not fit in the memory budget; the message says
// what lifts it (--max-memory, another solver, a coarser mesh).
Status require_memory(double bytes, const std::string& what);

}  // namespace fiberfluid::solve
