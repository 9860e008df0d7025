// SPDX-License-Identifier: GPL-3.0-or-later
// dense-lu: the paper's method, LU of the whole reduced bordered system.
#include <chrono>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/dense_lu.hpp"

namespace fiberfluid::solve {
namespace {

class DenseLUSolver final : public LinearSolver {
 public:
  SolverKind kind() const override { return SolverKind::DenseLU; }

  Status analyze_pattern(const model::BorderedSystem& system) override {
    const double n = system.num_unknowns();
    // The assembled matrix and its LU factors.
    return require_memory(2.0 * 8.0 * n * n,
                          "the dense LU of " + std::to_string(system.num_unknowns()) + " unknowns");
  }

  Status factorize(const model::BorderedSystem& system) override {
    const Eigen::MatrixXd A = system.dense_matrix();
    const auto start = std::chrono::steady_clock::now();
    const Status status = lu_.factorize(A);
    statistics_.factorization_kernel_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!status.ok) return status;
    const double n = system.num_unknowns();
    statistics_.factorization_flops += 2.0 / 3.0 * n * n * n;
    return {};
  }

  Status solve(const Eigen::VectorXd& rhs, Eigen::VectorXd* solution) override {
    *solution = lu_.solve(rhs);
    ++statistics_.solves;
    return {};
  }

 private:
  DenseLU lu_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_dense_lu_solver() { return std::make_unique<DenseLUSolver>(); }

}  // namespace fiberfluid::solve
