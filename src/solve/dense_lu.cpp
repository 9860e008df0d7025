// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/dense_lu.hpp"

#include <cstddef>
#include <cstdio>
#include <limits>
#include <stdexcept>

extern "C" {
// LAPACK (Fortran) entry points; the trailing size_t is the hidden length of
// each character argument.
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info, std::size_t trans_len);
double dlange_(const char* norm, const int* m, const int* n, const double* a, const int* lda,
               double* work, std::size_t norm_len);
void dgecon_(const char* norm, const int* n, const double* a, const int* lda, const double* anorm,
             double* rcond, double* work, int* iwork, int* info, std::size_t norm_len);
}

namespace fiberfluid::solve {

Status DenseLU::factorize(const Eigen::MatrixXd& A) {
  if (A.rows() != A.cols()) throw std::invalid_argument("DenseLU: the matrix must be square");
  factored_ = false;
  const int n = static_cast<int>(A.rows());
  lu_ = A;
  pivots_.assign(static_cast<size_t>(n), 0);
  std::vector<double> work(static_cast<size_t>(4 * n) + 1);
  std::vector<int> iwork(static_cast<size_t>(n) + 1);
  const char norm = '1';
  const double anorm = dlange_(&norm, &n, &n, A.data(), &n, work.data(), 1);
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

Eigen::VectorXd DenseLU::solve(const Eigen::VectorXd& b) const {
  if (!factored_) throw std::logic_error("DenseLU::solve called without a successful factorize");
  const int n = static_cast<int>(lu_.rows()), nrhs = 1;
  Eigen::VectorXd x = b;
  int info = 0;
  const char trans = 'N';
  dgetrs_(&trans, &n, &nrhs, lu_.data(), &n, pivots_.data(), x.data(), &n, &info, 1);
  return x;
}

}  // namespace fiberfluid::solve
