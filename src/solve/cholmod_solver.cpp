// SPDX-License-Identifier: GPL-3.0-or-later
// cholmod: a sparse Cholesky (SuiteSparse) per axis block, shared when the
// blocks are equal, and the Schur complement on P. Efficient when the fiber
// blocks are sparse (surface tension only, or pruned fibers); the all-pairs
// bulk fibers make a block dense, which it handles, at dense cost.
#include <vector>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/schur_solver.hpp"
#include "fiberfluid/solve/sparse_cholesky.hpp"

namespace fiberfluid::solve {
namespace {

class CholmodSolver final : public SchurSolver {
 public:
  SolverKind kind() const override { return SolverKind::Cholmod; }

  Status analyze_pattern(const model::BorderedSystem& system) override {
    double bytes = 0.0;
    for (int a = 0; a < system.num_blocks(); ++a) {
      const double m = system.block_size(a);
      // Dense blocks: every pair is a nonzero (12 bytes each), and the factor is dense too.
      if (system.dense_blocks()) bytes += 12.0 * m * m + 8.0 * m * m / 2.0;
    }
    return require_memory(bytes, "CHOLMOD on the dense bulk blocks");
  }

 protected:
  Status factorize_K(const model::BorderedSystem& system) override {
    const int count = system.blocks_equal() ? 1 : system.num_blocks();
    factors_.resize(static_cast<size_t>(count));
    offsets_ = system.block_offsets();
    for (int a = 0; a < count; ++a) {
      const Status status = factors_[static_cast<size_t>(a)].factorize(system.sparse_block(a));
      if (!status.ok)
        return Status::failure("cholmod: " + system.block_name(a) + ": " + status.message);
    }
    return {};
  }

  Status solve_K(const Eigen::VectorXd& f, Eigen::VectorXd* w) override {
    w->resize(f.size());
    for (size_t a = 0; a + 1 < offsets_.size(); ++a) {
      const int n = offsets_[a + 1] - offsets_[a];
      if (n == 0) continue;
      const SparseCholesky& factor = factors_[factors_.size() == 1 ? 0 : a];
      w->segment(offsets_[a], n) = factor.solve(f.segment(offsets_[a], n));
    }
    return {};
  }

 private:
  std::vector<SparseCholesky> factors_;
  std::vector<int> offsets_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_cholmod_solver() { return std::make_unique<CholmodSolver>(); }

}  // namespace fiberfluid::solve
