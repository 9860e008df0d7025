// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/dense_lu.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

extern "C" {
// LAPACK (Fortran) entry points; the trailing size_t is the hidden length of
// each character argument.
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info, std::size_t trans_len);
void strsv_(const char* uplo, const char* trans, const char* diag, const int* n, const float* a,
            const int* lda, float* x, const int* incx, std::size_t uplo_len, std::size_t trans_len,
            std::size_t diag_len);
void dtrmv_(const char* uplo, const char* trans, const char* diag, const int* n, const double* a,
            const int* lda, double* x, const int* incx, std::size_t uplo_len, std::size_t trans_len,
            std::size_t diag_len);
double dlange_(const char* norm, const int* m, const int* n, const double* a, const int* lda,
               double* work, std::size_t norm_len);
void dgecon_(const char* norm, const int* n, const double* a, const int* lda, const double* anorm,
             double* rcond, double* work, int* iwork, int* info, std::size_t norm_len);
}

namespace fiberfluid::solve {

Status DenseLU::factorize(Eigen::MatrixXd A) {
  if (A.rows() != A.cols()) throw std::invalid_argument("DenseLU: the matrix must be square");
  factored_ = single_ = false;
  lu_single_.resize(0, 0);
  rounding_stretch_ = 0.0;
  const int n = static_cast<int>(A.rows());
  pivots_.assign(static_cast<size_t>(n), 0);
  std::vector<double> work(static_cast<size_t>(4 * n) + 1);
  std::vector<int> iwork(static_cast<size_t>(n) + 1);
  const char norm = '1';
  const double anorm = dlange_(&norm, &n, &n, A.data(), &n, work.data(), 1);
  lu_ = std::move(A);
  int info = 0;
  dgetrf_(&n, &n, lu_.data(), &n, pivots_.data(), &info);
  if (info > 0)
    return Status::failure("the system matrix is singular (zero pivot at unknown " +
                           std::to_string(info - 1) + ")");
  dgecon_(&norm, &n, lu_.data(), &n, &anorm, &rcond_, work.data(), iwork.data(), &info, 1);
  if (!(rcond_ >= 10 * std::numeric_limits<double>::epsilon())) {
    char rcond[32];
    std::snprintf(rcond, sizeof rcond, "%.3g", rcond_);
    return Status::failure(std::string("the system matrix is numerically singular (reciprocal "
                                       "condition ") +
                           rcond + ")");
  }
  factored_ = true;
  return {};
}

// A = P L U times x in double, from the factors (dgetrf's row interchanges
// undone in reverse order).
Eigen::VectorXd DenseLU::multiply(const Eigen::VectorXd& x) const {
  const int n = static_cast<int>(lu_.rows()), one = 1;
  Eigen::VectorXd y = x;
  dtrmv_("U", "N", "N", &n, lu_.data(), &n, y.data(), &one, 1, 1, 1);
  dtrmv_("L", "N", "U", &n, lu_.data(), &n, y.data(), &one, 1, 1, 1);
  for (int i = n - 1; i >= 0; --i) std::swap(y[i], y[pivots_[static_cast<size_t>(i)] - 1]);
  return y;
}

bool DenseLU::round_to_single() {
  if (!factored_) throw std::logic_error("DenseLU::round_to_single called without a factorize");
  if (single_) return true;
  const Eigen::Index n = lu_.rows();
  DenseLU rounded;  // the same pivots, the factors rounded
  rounded.lu_single_ = lu_.cast<float>();
  rounded.pivots_ = pivots_;
  rounded.rcond_ = rcond_;
  rounded.factored_ = rounded.single_ = true;
  // E = A M^-1 - I for the rounded factors M: a few power steps from a fixed
  // pseudo-random vector find its largest stretch, as GMRES would.
  Eigen::VectorXd v(n);
  std::uint64_t seed = 88172645463325252ULL;  // xorshift64
  for (Eigen::Index i = 0; i < n; ++i) {
    seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
    v[i] = static_cast<double>(seed >> 11) * 0x1p-53 - 0.5;
  }
  double stretch = 0.0;
  for (int step = 0; step < kRoundingPowerSteps; ++step) {
    const Eigen::VectorXd w = multiply(rounded.solve(v)) - v;
    stretch = std::max(stretch, w.norm() / v.norm());
    if (!(stretch <= kMostRoundingStretch)) return false;
    if (w.norm() == 0.0) break;
    v = w / w.norm();
  }
  *this = std::move(rounded);
  rounding_stretch_ = stretch;
  return true;
}

Eigen::VectorXd DenseLU::solve(const Eigen::VectorXd& b) const {
  if (!factored_) throw std::logic_error("DenseLU::solve called without a successful factorize");
  if (single_) {
    // dgetrs's steps in single precision: the row interchanges, then L
    // (unit diagonal) and U.
    const int n = static_cast<int>(lu_single_.rows()), one = 1;
    Eigen::VectorXf x = b.cast<float>();
    for (int i = 0; i < n; ++i) std::swap(x[i], x[pivots_[static_cast<size_t>(i)] - 1]);
    strsv_("L", "N", "U", &n, lu_single_.data(), &n, x.data(), &one, 1, 1, 1);
    strsv_("U", "N", "N", &n, lu_single_.data(), &n, x.data(), &one, 1, 1, 1);
    return x.cast<double>();
  }
  const int n = static_cast<int>(lu_.rows()), nrhs = 1;
  Eigen::VectorXd x = b;
  int info = 0;
  const char trans = 'N';
  dgetrs_(&trans, &n, &nrhs, lu_.data(), &n, pivots_.data(), x.data(), &n, &info, 1);
  return x;
}

}  // namespace fiberfluid::solve
