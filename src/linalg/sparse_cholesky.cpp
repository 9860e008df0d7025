// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/linalg/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>

namespace fiberfluid::linalg {

struct SparseCholesky::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  bool analyzed = false;
  bool empty = false;  // no unknowns (everything held): CHOLMOD would crash on it
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {
  impl_->llt.cholmod().print = 0;  // failures come back as a Status, not as printed text
}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze_pattern(const Eigen::SparseMatrix<double>& A) {
  impl_->empty = A.rows() == 0;
  if (!impl_->empty) impl_->llt.analyzePattern(A);
  impl_->analyzed = true;
}

Status SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  if (!impl_->analyzed) analyze_pattern(A);
  if (impl_->empty) return {};
  impl_->llt.factorize(A);
  if (impl_->llt.info() != Eigen::Success)
    return Status::failure("CHOLMOD: the matrix is not positive definite");
  return {};
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const {
  if (impl_->empty) return Eigen::VectorXd(0);
  return impl_->llt.solve(b);
}

}  // namespace fiberfluid::linalg
