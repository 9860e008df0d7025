// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/SparseCore>
#include <memory>

#include "fiberfluid/linalg/status.hpp"

namespace fiberfluid::linalg {

// Sparse Cholesky of a symmetric positive definite matrix by SuiteSparse's
// CHOLMOD (supernodal, fill-reducing ordering). CHOLMOD's headers stay in
// the .cpp.
class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  // Symbolic analysis of the pattern, reused while the pattern is the same.
  void analyze_pattern(const Eigen::SparseMatrix<double>& A);
  // Fails when the matrix is not positive definite.
  Status factorize(const Eigen::SparseMatrix<double>& A);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fiberfluid::linalg
