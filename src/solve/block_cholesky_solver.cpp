// SPDX-License-Identifier: GPL-3.0-or-later
// block-cholesky: one dense Cholesky (LAPACK dpotrf) per axis block, shared
// when the blocks are equal, and the Schur complement on P. In single
// precision (spotrf) as the Newton-Krylov preconditioner: half the memory and
// time of its factorisation and solves, while GMRES keeps the tangent exact.
#include <chrono>
#include <type_traits>
#include <vector>

#include "fiberfluid/solve/backends.hpp"
#include "fiberfluid/solve/cholesky_solve.hpp"
#include "fiberfluid/solve/schur_solver.hpp"

extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
void spotrf_(const char* uplo, const int* n, float* a, const int* lda, int* info, std::size_t);
}

namespace fiberfluid::solve {
namespace {

// LAPACK's Cholesky factorisation by the factor's scalar type; the solves are
// cholesky_solve_in_place's.
void potrf(int n, double* a, int* info) { dpotrf_("L", &n, a, &n, info, 1); }
void potrf(int n, float* a, int* info) { spotrf_("L", &n, a, &n, info, 1); }

template <class Scalar>
class BlockCholeskySolver final : public SchurSolver {
 public:
  using Factor = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  SolverKind kind() const override { return SolverKind::BlockCholesky; }

  Status analyze_pattern(const model::BorderedSystem& system) override {
    const double n = system.largest_block();
    const int factors = system.blocks_equal() ? 1 : system.num_blocks();
    return require_memory(sizeof(Scalar) * n * n * factors,  // each block factored where it lies
                          "block Cholesky with " + std::to_string(factors) + " dense " +
                              std::to_string(system.largest_block()) + "-square factors");
  }

 protected:
  Status factorize_K(const model::BorderedSystem& system) override {
    const int count = system.blocks_equal() ? 1 : system.num_blocks();
    factors_.clear();
    offsets_ = system.block_offsets();
    for (int a = 0; a < count; ++a) {
      // The block filled in the factor's precision and factored where it lies
      // (no copy of N^2 entries).
      Factor K;
      if constexpr (std::is_same_v<Scalar, double>)
        K = system.dense_block(a);
      else
        K = system.dense_block_single(a);
      const int n = static_cast<int>(K.rows());
      int info = 0;
      const auto start = std::chrono::steady_clock::now();
      if (n > 0) potrf(n, K.data(), &info);
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
    Vector x = f.cast<Scalar>();
    if (factors_.size() == 1) {
      // One factor for equal blocks: the axes are the columns of one
      // multi-right-hand-side solve, a single pass over the factor.
      const int n = offsets_[1] - offsets_[0];
      const int nrhs = static_cast<int>(offsets_.size()) - 1;
      cholesky_solve_in_place(n, factors_[0].data(), x.data(), nrhs, n);
    } else {
      for (size_t a = 0; a + 1 < offsets_.size(); ++a)
        cholesky_solve_in_place(offsets_[a + 1] - offsets_[a], factors_[a].data(),
                                x.data() + offsets_[a], 1, 0);
    }
    *w = x.template cast<double>();
    return {};
  }

 private:
  std::vector<Factor> factors_;
  std::vector<int> offsets_;  // block starts, then the end
};

}  // namespace

std::unique_ptr<LinearSolver> make_block_cholesky_solver(bool single_precision) {
  if (single_precision) return std::make_unique<BlockCholeskySolver<float>>();
  return std::make_unique<BlockCholeskySolver<double>>();
}

}  // namespace fiberfluid::solve
