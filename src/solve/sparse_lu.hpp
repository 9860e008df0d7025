// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/SparseCore>
#include <memory>

#include "fiberfluid/solve/status.hpp"

namespace fiberfluid::solve {

// Sparse LU with partial pivoting of a square matrix by SuiteSparse's
// UMFPACK (unsymmetric multifrontal, fill-reducing column ordering, BLAS-3
// fronts): the Newton tangent of a horizon's fibers, which is sparse but
// neither symmetric (follower loads) nor definite (the bordered pressure
// row, fibers in compression). UMFPACK's headers stay in the .cpp.
class SparseLU {
 public:
  SparseLU();
  ~SparseLU();
  SparseLU(SparseLU&&) noexcept;
  SparseLU& operator=(SparseLU&&) noexcept;

  // Symbolic analysis when the pattern changed (or on the first call), then
  // the numeric factorisation. Fails when the matrix is singular or its
  // reciprocal condition estimate is below 10 machine epsilons.
  Status factorize(const Eigen::SparseMatrix<double>& A);
  // Requires a successful factorize().
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // UMFPACK's estimates from the last factorisation.
  double reciprocal_condition() const;
  double factor_entries() const;  // nonzeros of L and U

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fiberfluid::solve
