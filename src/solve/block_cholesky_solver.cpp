// SPDX-License-Identifier: GPL-3.0-or-later
// block-cholesky: one dense Cholesky (LAPACK dpotrf) per axis block, shared
// when the blocks are equal, and the Schur complement on P.
#include <chrono>
#include <vector>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/schur_solver.hpp"

extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
void dpotrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda,
             double* b, const int* ldb, int* info, std::size_t);
void dtrsv_(const char* uplo, const char* trans, const char* diag, const int* n, const double* a,
            const int* lda, double* x, const int* incx, std::size_t, std::size_t, std::size_t);
}

namespace fiberfluid::solve {
namespace {

class BlockCholeskySolver final : public SchurSolver {
 public:
  SolverKind kind() const override { return SolverKind::BlockCholesky; }

  Status analyze_pattern(const model::BorderedSystem& system) override {
    const double n = system.largest_block();
    const int factors = system.blocks_equal() ? 1 : system.num_blocks();
    return require_memory(8.0 * n * n * (factors + 1),
                          "block Cholesky with " + std::to_string(factors) + " dense " +
                              std::to_string(system.largest_block()) + "-square factors");
  }

 protected:
  Status factorize_K(const model::BorderedSystem& system) override {
    const int count = system.blocks_equal() ? 1 : system.num_blocks();
    factors_.clear();
    offsets_ = system.block_offsets();
    for (int a = 0; a < count; ++a) {
      Eigen::MatrixXd K = system.dense_block(a);
      const int n = static_cast<int>(K.rows());
      int info = 0;
      const char lower = 'L';
      const auto start = std::chrono::steady_clock::now();
      if (n > 0) dpotrf_(&lower, &n, K.data(), &n, &info, 1);
      statistics_.factorization_kernel_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (info > 0)
        return Status::failure("block-cholesky: " + system.block_name(a) +
                               " is not positive definite (leading minor " + std::to_string(info) +
                               ")");
      statistics_.factorization_flops += static_cast<double>(n) * n * n / 3.0;
      factors_.push_back(std::move(K));
    }
    return {};
  }

  Status solve_K(const Eigen::VectorXd& f, Eigen::VectorXd* w) override {
    *w = f;
    const char lower = 'L';
    if (factors_.size() == 1) {
      // One factor for equal blocks: the axes are the columns of one
      // multi-right-hand-side solve, a single pass over the factor.
      const int n = offsets_[1] - offsets_[0];
      const int nrhs = static_cast<int>(offsets_.size()) - 1;
      int info = 0;
      if (n > 0) dpotrs_(&lower, &n, &nrhs, factors_[0].data(), &n, w->data(), &n, &info, 1);
      return {};
    }
    // One right-hand side per factor: two triangular solves with dtrsv, which
    // reads the factor as it lies. dpotrs's dtrsm would first copy it into
    // packed panels, another pass over its memory: measured (OpenBLAS 0.3.21,
    // 2 cores), 0.16 ms against 0.44 ms at n = 993, 2.7 against 4.9 ms at
    // n = 2,562. With three right-hand sides dpotrs is as fast or faster.
    const char no = 'N', transposed = 'T', non_unit = 'N';
    const int one = 1;
    for (size_t a = 0; a + 1 < offsets_.size(); ++a) {
      const int n = offsets_[a + 1] - offsets_[a];
      if (n == 0) continue;
      double* x = w->data() + offsets_[a];
      dtrsv_(&lower, &no, &non_unit, &n, factors_[a].data(), &n, x, &one, 1, 1, 1);
      dtrsv_(&lower, &transposed, &non_unit, &n, factors_[a].data(), &n, x, &one, 1, 1, 1);
    }
    return {};
  }

 private:
  std::vector<Eigen::MatrixXd> factors_;
  std::vector<int> offsets_;  // block starts, then the end
};

}  // namespace

std::unique_ptr<LinearSolver> make_block_cholesky_solver() {
  return std::make_unique<BlockCholeskySolver>();
}

}  // namespace fiberfluid::solve
