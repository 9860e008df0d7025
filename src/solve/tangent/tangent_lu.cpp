// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/tangent/tangent_lu.hpp"

#include <algorithm>
#include <cmath>

namespace fiberfluid::solve {
namespace {

// The power of two that brings `largest` nearest 1 (1 for zero or non-finite).
double power_of_two(double largest) {
  return largest > 0.0 && std::isfinite(largest) ? std::exp2(-std::round(std::log2(largest))) : 1.0;
}

// J <- R J C with R, C diagonal powers of two (exact scaling): each row's
// largest entry near 1, then each column's (LAPACK's dgeequ rule).
void equilibrate(Eigen::MatrixXd& J, Eigen::VectorXd* rows, Eigen::VectorXd* columns) {
  *rows = Eigen::VectorXd::Ones(J.rows());
  *columns = Eigen::VectorXd::Ones(J.cols());
  for (Eigen::Index i = 0; i < J.rows(); ++i) {
    (*rows)[i] = power_of_two(J.row(i).cwiseAbs().maxCoeff());
    J.row(i) *= (*rows)[i];
  }
  for (Eigen::Index j = 0; j < J.cols(); ++j) {
    (*columns)[j] = power_of_two(J.col(j).cwiseAbs().maxCoeff());
    J.col(j) *= (*columns)[j];
  }
}

// The same for a sparse J, by its stored entries.
void equilibrate(Eigen::SparseMatrix<double>& J, Eigen::VectorXd* rows, Eigen::VectorXd* columns) {
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(J.rows());
  for (int c = 0; c < J.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it)
      largest[it.row()] = std::max(largest[it.row()], std::abs(it.value()));
  *rows = largest.unaryExpr([](double v) { return power_of_two(v); });
  *columns = Eigen::VectorXd::Ones(J.cols());
  for (int c = 0; c < J.outerSize(); ++c) {
    double column_largest = 0.0;
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it) {
      it.valueRef() *= (*rows)[it.row()];
      column_largest = std::max(column_largest, std::abs(it.value()));
    }
    (*columns)[c] = power_of_two(column_largest);
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it)
      it.valueRef() *= (*columns)[c];
  }
}

// The rows and columns of a full-layout sparse J that `dofs` leaves free.
Eigen::SparseMatrix<double> reduce(const model::DofMap& dofs,
                                   const Eigen::SparseMatrix<double>& J) {
  std::vector<int> reduced(static_cast<size_t>(J.rows()), -1);
  const std::vector<int>& full = dofs.full_index();
  for (size_t k = 0; k < full.size(); ++k)
    reduced[static_cast<size_t>(full[k])] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(J.nonZeros()));
  for (int c = 0; c < J.outerSize(); ++c) {
    const int rc = reduced[static_cast<size_t>(c)];
    if (rc < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(J, c); it; ++it) {
      const int rr = reduced[static_cast<size_t>(it.row())];
      if (rr >= 0) entries.emplace_back(rr, rc, it.value());
    }
  }
  const auto n = static_cast<Eigen::Index>(full.size());
  Eigen::SparseMatrix<double> out(n, n);
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace

Status TangentLU::factor(const model::Equilibrium& equilibrium, const Eigen::VectorXd& x,
                         const std::vector<double>& factors, const model::DofMap& dofs,
                         const AddedTangent& added, bool single) {
  if (storage_ == Storage::Sparse) {
    Eigen::SparseMatrix<double> full = equilibrium.sparse_tangent(x, factors);
    added.add_to(full);
    Eigen::SparseMatrix<double> J = reduce(dofs, full);
    equilibrate(J, &row_scale_, &column_scale_);
    if (!sparse_) sparse_ = std::make_unique<SparseLU>();
    return sparse_->factorize(J);
  }
  Eigen::MatrixXd full = equilibrium.tangent(x, factors);
  added.add_to(full);
  Eigen::MatrixXd J = dofs.reduce(full);
  equilibrate(J, &row_scale_, &column_scale_);
  dense_ = std::make_unique<DenseLU>();
  const Status status = dense_->factorize(std::move(J));
  if (status.ok && single) dense_->round_to_single();
  return status;
}

Eigen::VectorXd TangentLU::solve(const Eigen::VectorXd& b) const {
  const Eigen::VectorXd scaled = row_scale_.cwiseProduct(b);
  return column_scale_.cwiseProduct(storage_ == Storage::Sparse ? sparse_->solve(scaled)
                                                                : dense_->solve(scaled));
}

}  // namespace fiberfluid::solve
